// The light's depth pass, for the head and the hair: the distance along the light's axis.
in float vDepth;
layout(location = 0) out float oDepth;
void main() { oDepth = vDepth; }
