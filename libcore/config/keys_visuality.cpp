// The keys of Visuality Info (the hair's reflectance), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

Section<Visuality> makeVisuality() {
  using V = Visuality;
  const Range colorRange = Range::closed(0.0, 1000.0);
  return makeSection<V>(
      "Visuality", "Visuality Info", "VisualityInfo",
      {vectorKey<V, 3>({"AmbientColor", "", "ambient reflectance of the hair"}, &V::ambientColor, "r g b",
                       colorRange),
       vectorKey<V, 3>({"DiffuseColor", "", "diffuse reflectance of the hair"}, &V::diffuseColor, "r g b",
                       colorRange),
       vectorKey<V, 3>({"SpecularColor", "", "specular reflectance of the hair"}, &V::specularColor, "r g b",
                       colorRange),
       realKey<V>({"Glossiness", "", "specular exponent p"}, &V::glossiness, Range::closed(0.0, 100000.0)),
       realKey<V>({"AmbientMean", "", "hairgen shade: mean of the per-strand ambient coefficient (Anjyo)"},
                  &V::ambientMean, colorRange),
       realKey<V>({"AmbientDeviation", "", "hairgen shade: its standard deviation"}, &V::ambientDeviation,
                  colorRange)});
}

}  // namespace hairgen::keydecl
