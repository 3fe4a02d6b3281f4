#include "stages/preflight/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "libcore/model/shape_fit.h"
#include "libcore/render/views.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

// The bundled default coupe's view: camera and light as offsets from the target (configs/default).
const glm::dvec3 kViewDirection{0.32, 0.13, 0.52}, kLightOffset{0.6, 0.97, 0.8};

std::string area(double squareMetres) {
  return squareMetres >= 1.0 ? formatReal(std::round(squareMetres * 10) / 10) + " m²"
                             : formatReal(std::round(squareMetres * 1e4)) + " cm²";
}

// How far `p` is outside `shape`, metres (negative inside), to first order.
double outside(const CollisionShape& shape, const glm::dvec3& p) {
  const glm::dvec3 local = glm::transpose(shape.axes) * (p - shape.centre);
  const double minExtent = std::min(shape.halfExtents.x, std::min(shape.halfExtents.y, shape.halfExtents.z));
  if (shape.kind == ShapeKind::kCuboid) {
    const glm::dvec3 q = glm::abs(local) - shape.halfExtents;
    return std::max(q.x, std::max(q.y, q.z));
  }
  return (glm::length(local / shape.halfExtents) - 1.0) * minExtent;
}

}  // namespace

void fitCollision(Collision& collision, const Mesh& wick, const Mesh* head) {
  for (CollisionShape& shape : collision.shapes) {
    if (!shape.fitted) continue;
    const HeadFit fit = fitHead(head ? head->positions : std::vector<glm::vec3>{}, wick.positions,
                                shape.kind == ShapeKind::kSphere);
    shape.centre = fit.centre;
    shape.halfExtents = fit.semiAxes;
    shape.axes = glm::dmat3(1.0);
  }
}

// The whorl's direction from the fitted cranium's centre, in units of its semi-axes: up 2, back 1 (heads
// face +z), a point of its surface 27° behind its top. Chosen so that on the bundled head it is the point
// the default coupe was groomed with by eye.
const glm::dvec3 kWhorl = glm::dvec3(0.0, 2.0, -1.0) / std::sqrt(5.0);

glm::dvec3 headWhorl(const Mesh& wick, const Mesh* head) {
  const HeadFit fit = fitHead(head ? head->positions : std::vector<glm::vec3>{}, wick.positions, false);
  const bool found = glm::all(glm::greaterThan(fit.semiAxes, glm::dvec3(0.0))) &&
                     glm::all(glm::lessThan(fit.semiAxes, glm::dvec3(1e6)));
  if (!found)
    throw InputError("RootFlow away-from auto: no head could be fitted to " +
                     std::string(head ? "the head and the wick" : "the wick") +
                     " (too few points, or a flat patch); name the point, RootFlow away-from X Y Z");
  return fit.centre + fit.semiAxes * kWhorl;
}

void fitRootFlow(Hairstyle& style, const Mesh& wick, const Mesh* head) {
  if (!style.rootFlow.fitted) return;
  style.rootFlow.value = headWhorl(wick, head);
  style.rootFlow.resolved = true;
}

namespace {

std::string tenthOfMillimetre(double v) {
  return formatReal(std::round(v * 1e4) / 1e4);
}

}  // namespace

std::string fittedRootFlowLine(const Hairstyle& style) {
  // To a micrometre: near the whorl a follicle's lean turns fast with the point, and a tenth of a
  // millimetre moved the default coupe's tips by up to 4 mm.
  auto micrometre = [](double v) { return formatReal(std::round(v * 1e6) / 1e6); };
  const glm::dvec3& p = style.rootFlow.value;
  return "RootFlow away-from " + micrometre(p.x) + " " + micrometre(p.y) + " " + micrometre(p.z);
}

std::vector<std::string> fittedShapeLines(const Collision& collision) {
  std::vector<std::string> lines;
  auto mm = tenthOfMillimetre;
  for (const CollisionShape& s : collision.shapes) {
    if (!s.fitted) continue;
    std::string line = std::string(s.kind == ShapeKind::kSphere ? "Sphere" : "Ellipsoid") + " " +
                       formatReal(s.envelopeGrowth) + " " + formatReal(s.penalty) + " " + mm(s.centre.x) +
                       " " + mm(s.centre.y) + " " + mm(s.centre.z) + " " + mm(s.halfExtents.x);
    if (s.kind != ShapeKind::kSphere)
      line += " " + mm(s.halfExtents.y) + " " + mm(s.halfExtents.z) + " 1 0 0 0 1 0 0 0 1";
    lines.push_back(line);
  }
  return lines;
}

std::vector<SceneFinding> checkScene(const Config& config, const Mesh& wick, const Mesh* head) {
  std::vector<SceneFinding> out;
  if (wick.positions.empty()) return out;
  const std::string wickName = config.setup.wickModel.path.filename().string();
  const bool unitsGiven = config.setup.meshConversion.metresPerUnit.has_value();
  // The unit that would make a size plausible, when one does.
  struct Unit {
    const char* name;
    double metres;
  };
  const Unit units[] = {{"cm", 0.01}, {"mm", 0.001}, {"in", 0.0254}};
  auto suggestion = [&](double size, double lo, double hi, int power) -> std::string {
    if (unitsGiven) return "";
    for (const Unit& u : units)
      if (size * std::pow(u.metres, power) >= lo && size * std::pow(u.metres, power) <= hi)
        return std::string("looks like ") +
               (u.name == std::string("in")   ? "inches"
                : u.name == std::string("cm") ? "centimetres"
                                              : "millimetres") +
               "; set MeshUnits " + u.name;
    return "";
  };
  const Bounds box = bounds(wick.positions);
  const glm::dvec3 span = glm::dvec3(box.max) - glm::dvec3(box.min);
  const double diagonal = glm::length(span);
  if (!wick.triangles.empty()) {
    const double a = surfaceArea(wick);
    if (a > kMaxWickArea) {
      std::string why = suggestion(a, 0.015, kMaxWickArea, 2);
      out.push_back({true, "the wick " + wickName + " has " + area(a) + " of surface: " +
                               (why.empty() ? "more than a whole head (a scalp has 200-600 cm², a head "
                                              "up to 0.6 m²); check MeshUnits"
                                            : why)});
    } else if (a < kMinWickArea) {
      out.push_back({false, "the wick " + wickName + " has only " + area(a) +
                                " of surface, less than the 20 cm² of a small patch of scalp (a whole "
                                "scalp has 200-600 cm²); check MeshUnits"});
    }
  } else if (diagonal > kMaxWickSpan) {
    std::string why = suggestion(diagonal, kMinWickSpan * 2, kMaxWickSpan, 1);
    out.push_back({true, "the wick " + wickName + " spans " + formatReal(std::round(diagonal * 100) / 100) +
                             " m: " + (why.empty() ? "it is not a scalp; check MeshUnits" : why)});
  }
  if (head && !head->positions.empty()) {
    const Bounds hb = bounds(head->positions);
    const double headSpan = glm::length(glm::dvec3(hb.max) - glm::dvec3(hb.min));
    if (headSpan > 2.0 || headSpan < 0.05)
      out.push_back({false, "the head " + config.setup.headModel.path.filename().string() + " spans " +
                                formatReal(std::round(headSpan * 1000) / 1000) +
                                " m, not a head's size; check MeshUnits"});
  }
  // Far from the origin for its size: single-precision positions lose the hair's fine detail.
  const glm::dvec3 centre = 0.5 * (glm::dvec3(box.min) + glm::dvec3(box.max));
  if (glm::length(centre) > 50.0 * std::max(diagonal, 1e-6))
    out.push_back({false, "the wick lies " + formatReal(std::round(glm::length(centre) * 100) / 100) +
                              " m from the origin, far for its size of " +
                              formatReal(std::round(diagonal * 1000) / 1000) +
                              " m; move it near the origin (positions are single precision)"});
  // Outside every collision shape: the shapes were made for another head (or are in other units).
  const CollisionShape* near = nullptr;
  size_t touching = 0;
  for (const glm::vec3& p : wick.positions) {
    for (const CollisionShape& s : config.collision.shapes) {
      if (s.penalty > 0.0 && outside(s, glm::dvec3(p)) < 0.03) {
        ++touching;
        near = &s;
        break;
      }
    }
  }
  const size_t penalising = std::count_if(config.collision.shapes.begin(), config.collision.shapes.end(),
                                          [](const CollisionShape& s) { return s.penalty > 0.0; });
  const auto& shapes = config.collision.shapes;
  const bool fitted =
      std::any_of(shapes.begin(), shapes.end(), [](const CollisionShape& s) { return s.fitted; });
  if (penalising > 0 && touching * 2 < wick.positions.size())
    out.push_back({false, "most of the wick lies more than 3 cm outside every collision shape (" +
                              std::to_string(wick.positions.size() - touching) + " of " +
                              std::to_string(wick.positions.size()) + " follicles): " +
                              (fitted ? "the shapes fitted to the head's cranium do not reach it; check "
                                        "WickGroup (the scalp's faces) and HeadModel"
                                      : "the shapes fit another head; use Ellipsoid VOLUME PENALTY auto")});
  (void)near;
  // Follicles lean away from RootFlow's point, a whorl on the scalp: one far from every follicle (the
  // bundled head's whorl, in a Hairstyle Info made for it, on another head) leans them all one way, or
  // the top of the head back. The bundled coupes' lie within a centimetre of a follicle; a point a
  // quarter of the wick's size away (at least 3 cm) is no whorl of this scalp.
  const Hairstyle& style = config.hairstyle;
  // The nearest follicle, asked for only where the follicles lean away from the point.
  auto nearestToFlow = [&] {
    double nearest = std::numeric_limits<double>::infinity();
    for (const glm::vec3& p : wick.positions)
      nearest = std::min(nearest, glm::length(glm::dvec3(p) - style.rootFlow.value));
    return nearest;
  };
  double nearestFollicle = 0.0;
  if (style.rootTilt > 0.0 && style.rootFlow.kind == RootFlow::Kind::kAwayFrom && !style.rootFlow.fitted &&
      !wick.positions.empty() && (nearestFollicle = nearestToFlow()) > std::max(0.25 * diagonal, 0.03)) {
    auto point = [](const glm::dvec3& p) {
      auto r = [](double v) { return formatReal(std::round(v * 1000.0) / 1000.0); };
      return r(p.x) + " " + r(p.y) + " " + r(p.z);
    };
    out.push_back({false, "RootFlow's point (" + point(style.rootFlow.value) + ") lies " +
                              formatReal(std::round(nearestFollicle * 100) / 100) +
                              " m from the nearest follicle, so it is no whorl of this scalp and the "
                              "follicles lean one way; for this head, RootFlow away-from auto (its whorl; "
                              "hairgen check prints the point)"});
  }
  // The camera: does it see the wick?
  if (!config.render.cameraAuto) {
    const glm::dvec3 view = glm::normalize(config.render.cameraTarget - config.render.cameraPosition);
    const glm::dvec3 toWick = centre - config.render.cameraPosition;
    const double cosAngle = glm::dot(view, glm::normalize(toWick));
    const double half = glm::radians(config.render.fieldOfView) * 0.5 *
                        std::max(1.0, double(config.render.resolution.x) / config.render.resolution.y);
    const double reach = std::atan2(0.5 * diagonal, glm::length(toWick));
    if (glm::length(toWick) < 1e-9 || std::acos(std::clamp(cosAngle, -1.0, 1.0)) > half + reach)
      out.push_back({false, "neither hair nor head is in the camera's view (CameraPosition " +
                                formatReal(config.render.cameraPosition.x) + " " +
                                formatReal(config.render.cameraPosition.y) + " " +
                                formatReal(config.render.cameraPosition.z) +
                                "); set CameraPosition auto to frame them"});
  }
  return out;
}

void frameScene(RenderSettings& r, const Strands& hair, const Mesh* head) {
  if (hair.points.empty() && (!head || head->positions.empty())) return;
  const BoundingSphere sphere = boundingSphere(hair, head);
  const double fov = glm::radians(r.fieldOfView) * std::min(1.0, double(r.resolution.x) / r.resolution.y);
  const double distance = sphere.radius / std::sin(0.5 * fov) * 1.05;
  r.cameraTarget = sphere.centre;
  r.cameraUp = {0.0, 1.0, 0.0};
  r.cameraPosition = sphere.centre + glm::normalize(kViewDirection) * distance;
  r.lightPosition = sphere.centre + kLightOffset * (distance / glm::length(kViewDirection));
}

}  // namespace hairgen
