// The keys of the Setup (the job's files, meshes and flags), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

namespace {

// MeshUnits and MeshUpAxis enter the digest only when given, so that the digest of a Setup written
// before they existed does not change.
Key<Setup> meshUnitsKey() {
  return customKey<Setup>(
      {"MeshUnits", "", "the length unit of the wick and head OBJs: m, cm, mm, in, or metres per unit"},
      "m | cm | mm | in | factor", "[1e-06, 1000] metres per unit",
      [](SectionReader& r, Setup& s) {
        const ConfigLine* line = r.line("MeshUnits");
        if (!line) return;
        std::optional<double> unit =
            line->values.size() == 1 ? parseLengthUnit(line->values[0]) : std::nullopt;
        if (!unit)
          throw r.error(*line, "MeshUnits takes m, cm, mm, in or a number of metres per unit from " +
                                   formatReal(kMinMetresPerUnit) + " m (a micrometre) to " +
                                   formatReal(kMaxMetresPerUnit) + " m (a kilometre)");
        s.meshConversion.metresPerUnit = unit;
      },
      [](const Setup& s) {
        return s.meshConversion.metresPerUnit && *s.meshConversion.metresPerUnit != 1.0
                   ? std::vector<std::string>{formatReal(*s.meshConversion.metresPerUnit)}
                   : std::vector<std::string>{};
      });
}

Key<Setup> meshUpAxisKey() {
  return customKey<Setup>(
      {"MeshUpAxis", "", "the up axis of the wick and head OBJs: z turns z-up to hairgen's +y up"}, "y | z",
      "",
      [](SectionReader& r, Setup& s) {
        const ConfigLine* line = r.line("MeshUpAxis");
        if (!line) return;
        std::optional<UpAxis> axis = line->values.size() == 1 ? parseUpAxis(line->values[0]) : std::nullopt;
        if (!axis) throw r.error(*line, "MeshUpAxis takes y or z");
        s.meshConversion.upAxis = axis;
      },
      [](const Setup& s) {
        return s.meshConversion.upAxis == UpAxis::kZ ? std::vector<std::string>{"z"}
                                                     : std::vector<std::string>{};
      });
}

// HeadModel none (any case) or "" is no head, as when the Setup names none.
Key<Setup> headModelKey() {
  Key<Setup> key = pathKey<Setup>(
      {"HeadModel", "", "the head OBJ: rendered, and shadows the hair; none (or \"\") for no head"},
      &Setup::headModel);
  key.spec.value = "path | none";
  key.read = [path = key.read](SectionReader& r, Setup& s) {
    const ConfigLine* line = r.line("HeadModel");
    if (line && line->values.size() == 1 && toLower(line->values[0]) == "none") return;
    path(r, s);
  };
  return key;
}

}  // namespace

Section<Setup> makeSetup() {
  auto notInDigest = [](Key<Setup> key) {
    key.spec.inDigest = false;
    return key;
  };
  return makeSection<Setup>(
      "Setup", "Setup", "",
      {notInDigest(
           boolKey<Setup>({"Load", "", "read the coupe from LoadFile instead of growing it"}, &Setup::load)),
       notInDigest(boolKey<Setup>({"Save", "", "write the coupe to SaveFile"}, &Setup::save)),
       pathKey<Setup>({"LoadFile", "", "the coupe to load (.hair, .gltf, .glb)", {"LoadPath"}},
                      &Setup::loadFile),
       pathKey<Setup>({"SaveFile", "", "where to save the coupe (.hair, .gltf, .glb)", {"SavePath"}},
                      &Setup::saveFile),
       pathKey<Setup>({"HairstyleInfo", "", "the Hairstyle Info file"}, &Setup::hairstyleInfo),
       pathKey<Setup>({"CollisionInfo", "", "the Collision Info file"}, &Setup::collisionInfo),
       pathKey<Setup>({"VisualityInfo", "", "the Visuality Info file"}, &Setup::visualityInfo),
       pathKey<Setup>({"RenderInfo", "", "the Render Info file"}, &Setup::renderInfo),
       pathKey<Setup>({"DynamicsInfo", "", "the Dynamics Info file: naming one makes the hair move"},
                      &Setup::dynamicsInfo),
       pathKey<Setup>({"WickModel", "", "the wick OBJ: every vertex a follicle", {"HairModel"}},
                      &Setup::wickModel),
       headModelKey(),
       pathKey<Setup>({"HairVert", "",
                       "GLSL hair vertex stage of every pass, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::hairVert),
       pathKey<Setup>({"HairFrag", "",
                       "GLSL fragment stage shading the hair, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::hairFrag),
       pathKey<Setup>({"HeadVert", "",
                       "GLSL head vertex stage of every pass, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::headVert),
       pathKey<Setup>({"HeadFrag", "",
                       "GLSL fragment stage shading the head, in place of hairgen's (docs/rendering.md, "
                       "Custom shaders)"},
                      &Setup::headFrag),
       meshUnitsKey(), meshUpAxisKey(),
       customKey<Setup>(
           {"WickGroup", "",
            "grow only on the faces of this OBJ group, object or material of the wick (a whole head can be "
            "the wick)"},
           "name", "",
           [](SectionReader& r, Setup& s) {
             const ConfigLine* line = r.line("WickGroup");
             if (!line) return;
             if (line->values.size() != 1) throw r.error(*line, "WickGroup takes one name");
             s.wickGroup = line->values[0];
           },
           [](const Setup& s) {
             return s.wickGroup.empty() ? std::vector<std::string>{} : std::vector<std::string>{s.wickGroup};
           })},
      [](SectionReader& r, Setup& s) {
        if (s.load && !s.loadFile.given())
          throw InputError(r.where("Load"),
                           "Load is true but no LoadFile names the coupe to load; add `LoadFile PATH`");
        if (s.save && !s.saveFile.given())
          throw InputError(r.where("Save"),
                           "Save is true but no SaveFile names where to save; add `SaveFile PATH`");
        s.file = r.fileName();
      });
}

}  // namespace hairgen::keydecl
