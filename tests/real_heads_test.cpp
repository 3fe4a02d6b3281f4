// Real heads end to end (README, Real heads): a scalp generated here, moved to standing height and
// written in centimetres, z-up, and Blender units (metres, z-up), grown, interpolated and rendered by
// `hairgen run` with MeshUnits / MeshUpAxis, `Ellipsoid auto` and the automatic camera. Checks that the
// roots lie on the scalp where it really is (within 0.5 mm), that fewer than 1% of the hair points past
// 1 cm of arc length are inside the fitted head, and that the hair covers more than 5% of the image.
// Usage: real_heads_test HAIRGEN SOURCE_DIR WORK_DIR
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include "libcore/config/setup.h"
#include "libcore/io/exr_io.h"
#include "libcore/io/hair_cache.h"
#include "libcore/io/obj_io.h"
#include "libcore/model/shape_fit.h"
#include "stages/preflight/scene.h"
#include "tests/geometry_util.h"

namespace fs = std::filesystem;
using namespace hairgen;

namespace {

double distanceToMesh(const glm::dvec3& p, const Mesh& m) {
  double best = HUGE_VAL;
  for (const glm::uvec3& t : m.triangles)
    best =
        std::min(best, test::distanceToTriangle(p, glm::dvec3(m.positions[t.x]), glm::dvec3(m.positions[t.y]),
                                                glm::dvec3(m.positions[t.z])));
  return best;
}

struct Figures {
  double worstRoot = 0.0;       // metres from the scalp
  double insideFraction = 0.0;  // of the points past 1 cm of arc length
  double coverage = 0.0;        // of the image's pixels
};

// The three figures of a `hairgen run` output folder, against `scalp` (metres, y up) and the head
// fitted as `Ellipsoid auto` fits it.
Figures measure(const fs::path& out, const Mesh& scalp, const Mesh* head) {
  Figures f;
  const Strands coupe = readStrands(out / "coupe.hair");
  const Strands guides = readStrands(out / "guides.hair");
  for (const Strands* s : {&guides, &coupe})
    for (size_t i = 0; i < s->strandCount(); i += 7) {
      const glm::dvec3 root(s->points[s->firstPoint[i]]);
      double d = HUGE_VAL;
      if (scalp.triangles.empty())
        for (const glm::vec3& p : scalp.positions) d = std::min(d, glm::length(root - glm::dvec3(p)));
      else
        d = distanceToMesh(root, scalp);
      f.worstRoot = std::max(f.worstRoot, d);
    }
  Collision fitted;
  fitted.shapes.push_back(CollisionShape{});
  fitted.shapes[0].kind = ShapeKind::kEllipsoid;
  fitted.shapes[0].fitted = true;
  fitCollision(fitted, scalp, head);
  const CollisionShape& e = fitted.shapes[0];
  size_t counted = 0, inside = 0;
  for (size_t i = 0; i < coupe.strandCount(); ++i) {
    double arc = 0.0;
    for (uint32_t p = coupe.firstPoint[i] + 1; p < coupe.firstPoint[i + 1]; ++p) {
      arc += glm::length(coupe.points[p] - coupe.points[p - 1]);
      if (arc < 0.01) continue;
      ++counted;
      inside += glm::length((glm::dvec3(coupe.points[p]) - e.centre) / e.halfExtents) < 1.0;
    }
  }
  f.insideFraction = double(inside) / double(std::max<size_t>(counted, 1));
  const Image beauty = readImage(out / "beauty.exr");
  const std::vector<float>& opacity = beauty.plane("opacity.Y");
  size_t covered = 0;
  for (float o : opacity) covered += o > 0.0f;
  f.coverage = double(covered) / double(opacity.size());
  return f;
}

struct Variant {
  const char* name;
  double metresPerUnit;  // the file's unit
  bool zUp;
  const char* setupLines;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--measure") {  // --measure SETUP OUT: a run made by hand
    const Config config = loadConfig(argv[2], {}, SetupUse::kRun);
    MeshReadOptions options;
    options.group = config.setup.wickGroup;
    options.allowPoints = true;
    options.conversion = config.setup.meshConversion;
    const Mesh scalp = readObj(config.setup.wickModel.path, options);
    std::optional<Mesh> head;
    if (config.setup.headModel.given())
      head = readObj(config.setup.headModel.path, {"", false, options.conversion, "HeadModel"});
    const Figures f = measure(argv[3], scalp, head ? &*head : nullptr);
    std::printf(
        "roots within %.3f mm of the scalp, %.2f%% of points past 1 cm inside the fitted head, hair "
        "covers %.1f%% of the image\n",
        f.worstRoot * 1e3, f.insideFraction * 100, f.coverage * 100);
    return 0;
  }
  if (argc != 4) {
    std::cerr << "usage: real_heads_test HAIRGEN SOURCE_DIR WORK_DIR\n";
    return 2;
  }
  const std::string hairgen = argv[1];
  const fs::path source = fs::absolute(argv[2]), work = fs::absolute(argv[3]);
  fs::create_directories(work);
  // The truth: the bundled scalp, standing (its top at 1.75 m), in metres, y up.
  Mesh truth = readObj(source / "configs/assets/wick.obj");
  for (glm::vec3& p : truth.positions) p.y += 1.60f;
  const Variant variants[] = {
      {"standing", 1.0, false, ""},
      {"centimetres", 0.01, false, "MeshUnits cm\n"},
      {"z-up", 1.0, true, "MeshUpAxis z\n"},
      {"blender", 1.0, true, "MeshUnits m\nMeshUpAxis z\n"},
  };
  int failures = 0;
  for (const Variant& v : variants) {
    const fs::path dir = work / v.name;
    fs::create_directories(dir);
    // Written as a DCC would: the unit and the up axis of the variant ((x, y, z) y-up is (x, −z, y) z-up).
    Mesh file = truth;
    for (glm::vec3& p : file.positions) {
      if (v.zUp) p = {p.x, -p.z, p.y};
      p /= float(v.metresPerUnit);
    }
    for (glm::vec3& n : file.normals)
      if (v.zUp) n = {n.x, -n.z, n.y};
    {
      std::ofstream obj(dir / "scalp.obj");
      writeObj(file, obj, std::string("hairgen real_heads_test: ") + v.name);
      std::ofstream collision(dir / "collision.txt");
      collision << "Ellipsoid 0.02 10 auto\n";
      std::ofstream setup(dir / "setup.txt");
      setup << "HairstyleInfo " << (source / "configs/default/hairstyle.txt").string()
            << "\nCollisionInfo collision.txt\nWickModel scalp.obj\n"
            << v.setupLines;
    }
    const std::string command = "'" + hairgen + "' run '" + (dir / "setup.txt").string() + "' -o '" +
                                (dir / "out").string() +
                                "' --quiet --set Hairstyle.HairDensity=20 --set 'Render.Resolution=160 160'";
    if (std::system(command.c_str()) != 0) {
      std::cerr << "FAIL " << v.name << ": " << command << "\n";
      ++failures;
      continue;
    }
    const Figures f = measure(dir / "out", truth, nullptr);
    const double worstRoot = f.worstRoot, insideFraction = f.insideFraction, coverage = f.coverage;
    const bool ok = worstRoot < 0.0005 && insideFraction < 0.01 && coverage > 0.05;
    std::printf(
        "%s %s: roots within %.3f mm of the scalp, %.2f%% of points past 1 cm inside the fitted head, "
        "hair covers %.1f%% of the image\n",
        ok ? "ok  " : "FAIL", v.name, worstRoot * 1e3, insideFraction * 100, coverage * 100);
    failures += !ok;
  }
  // The centimetre scalp without MeshUnits: `hairgen check` refuses it at once, naming the unit.
  {
    const fs::path dir = work / "centimetres";
    std::ofstream(dir / "wrong.txt") << "HairstyleInfo "
                                     << (source / "configs/default/hairstyle.txt").string()
                                     << "\nCollisionInfo collision.txt\nWickModel scalp.obj\n";
    const std::string command = "'" + hairgen + "' check '" + (dir / "wrong.txt").string() + "' 2> '" +
                                (dir / "wrong.err").string() + "'";
    const auto start = std::chrono::steady_clock::now();
    const int status = std::system(command.c_str());
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::stringstream message;
    message << std::ifstream(dir / "wrong.err").rdbuf();
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 2 && seconds < 1.0 &&
                    message.str().find("MeshUnits cm") != std::string::npos;
    std::printf("%s check on the centimetre scalp: exit %d in %.2f s: %s", ok ? "ok  " : "FAIL",
                WIFEXITED(status) ? WEXITSTATUS(status) : -1, seconds, message.str().c_str());
    failures += !ok;
  }
  return failures ? 1 : 0;
}
