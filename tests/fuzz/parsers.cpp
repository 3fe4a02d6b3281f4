// tinygltf and tinyobjloader compiled from their headers into the fuzz build, so that ASan, UBSan and
// the fuzzer's coverage see inside the parsers the raw bytes go through. Production links Debian's
// shared libraries, built from these same headers; tinygltf's image decoding (stb_image, libstb) is
// linked but never called, as decodeGltf skips images.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>

#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
