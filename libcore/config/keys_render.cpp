// The keys of Render Info (camera, light and film), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

namespace {

Key<RenderSettings> resolutionKey() {
  return customKey<RenderSettings>(
      {"Resolution", "pixels", "width and height of the image"}, "width height", "[1, 16384]",
      [](SectionReader& r, RenderSettings& s) {
        std::vector<double> res =
            r.reals("Resolution", 2, std::vector<double>{double(s.resolution.x), double(s.resolution.y)},
                    Range::closed(1, 16384));
        if (res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]))
          throw InputError(r.where("Resolution"), "Resolution must be two whole numbers of pixels");
        s.resolution = glm::ivec2(static_cast<int>(res[0]), static_cast<int>(res[1]));
      },
      [](const RenderSettings& s) {
        return std::vector<std::string>{std::to_string(s.resolution.x) + " " +
                                        std::to_string(s.resolution.y)};
      });
}

}  // namespace

Section<RenderSettings> makeRender() {
  using R = RenderSettings;
  const Range colorRange = Range::closed(0.0, 1e6);
  return makeSection<R>(
      "Render", "Render Info", "RenderInfo",
      {resolutionKey(),
       customKey<R>(
           {"CameraPosition", "m",
            "where the camera is; auto frames the hair and the head from a three-quarter view, the light "
            "placed relative to it"},
           "auto | x y z", "",
           [](SectionReader& r, R& s) {
             const ConfigLine* line = r.line("CameraPosition");
             if (!line || (line->values.size() == 1 && toLower(line->values[0]) == "auto")) return;
             if (line->values.size() != 3) throw r.error(*line, "CameraPosition takes auto or x y z");
             s.cameraAuto = false;
             for (int i = 0; i < 3; ++i) s.cameraPosition[i] = r.checkReal(*line, i, {}, "position");
           },
           [](const R& s) {
             return std::vector<std::string>{s.cameraAuto ? std::string("auto") : join(s.cameraPosition)};
           }),
       vectorKey<R, 3>({"CameraTarget", "m", "the point the camera looks at"}, &R::cameraTarget, "x y z"),
       vectorKey<R, 3>({"CameraUp", "", "the camera's up direction"}, &R::cameraUp, "x y z"),
       realKey<R>({"FieldOfView", "degrees", "vertical field of view"}, &R::fieldOfView,
                  {0.0, 180.0, true, true}),
       vectorKey<R, 3>({"LightPosition", "m", "the point light"}, &R::lightPosition, "x y z"),
       vectorKey<R, 3>({"LightColor", "", "the light's colour and intensity"}, &R::lightColor, "r g b",
                       colorRange),
       realKey<R>({"AmbientIntensity", "", "ambient light"}, &R::ambientIntensity, colorRange),
       integerKey<R>({"Samples", "", "antialiasing samples per pixel (k² for k×k sub-pixels)"}, &R::samples,
                     1, 64),
       vectorKey<R, 4>({"LayerSizes", "m", "the depths of the four deep-opacity layers"}, &R::layerSizes,
                       "d1 d2 d3 d4", Range::positive()),
       realKey<R>({"StrandOpacity", "", "opacity of one strand where it covers a whole pixel"},
                  &R::strandOpacity, Range::closed(0.0, 1.0)),
       realKey<R>({"StrandWidth", "m", "on-screen diameter of a strand"}, &R::strandWidth,
                  {0.0, 1.0, true, false}),
       choiceKey<R, ShadingModel>({"ShadingModel", "", "how strands are lit (docs/rendering.md)"},
                                  &R::shadingModel, {std::begin(kShadingModels), std::end(kShadingModels)}),
       vectorKey<R, 3>({"Background", "", "the preview's background colour"}, &R::background, "r g b",
                       colorRange),
       vectorKey<R, 3>({"HeadColor", "", "Lambert albedo of the head"}, &R::headColor, "r g b",
                       Range::closed(0.0, 1.0)),
       realKey<R>(
           {"VoxelSize", "m", "hairgen shade: spacing of the density grid (large for caches in cm or mm)"},
           &R::voxelSize, {0.0, 1000.0, true, false}),
       integerKey<R>({"VolumePadding", "voxels", "hairgen shade: empty voxels around the hair"},
                     &R::volumePadding, 1, 64),
       realKey<R>(
           {"ShellDensity", "", "hairgen shade: the shell's density as a fraction of a typical hair point's"},
           &R::shellDensity, {0.0, 100.0, true, false}),
       realKey<R>({"VolumetricBlend", "", "0 = Kajiya-Kay, 1 = volumetric"}, &R::volumetricBlend,
                  Range::closed(0.0, 1.0))},
      [](SectionReader& r, R& s) {
        if (s.cameraAuto) return;  // the stage aims it
        if (glm::length(s.cameraTarget - s.cameraPosition) < 1e-9)
          throw InputError(r.where("CameraTarget"),
                           "CameraTarget equals CameraPosition; the camera needs a direction");
        if (glm::length(glm::cross(s.cameraUp, s.cameraTarget - s.cameraPosition)) < 1e-9)
          throw InputError(r.where("CameraUp"), "CameraUp is zero or parallel to the view direction");
      });
}

}  // namespace hairgen::keydecl
