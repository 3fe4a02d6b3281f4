// The parameters of hairgen's four thesis config files plus Render Info (DESIGN §4), as plain structs
// with defaults and units. Defaults are physically measured values (thesis Tables 1-3) wherever the
// thesis' example files carry something else, so a file that omits a key gets real hair.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/model/units.h"
#include "libcore/util/error.h"

namespace hairgen {

enum class StylingModel { kSuperHelix, kCantilever };
// How grow minimises a Super-Helix guide's energy: Rosenbrock's direct search (the thesis, the
// default) or BFGS on the energy's analytic gradient (README, Minimiser).
enum class Minimiser { kRosenbrock, kBfgs };
enum class ShadingModel { kKajiyaKay, kThesis, kAnjyo, kVolumetric };
// Every shading model, in the enum's order: the config's choices and the renderer's GLSL constants.
inline constexpr ShadingModel kShadingModels[] = {ShadingModel::kKajiyaKay, ShadingModel::kThesis,
                                                  ShadingModel::kAnjyo, ShadingModel::kVolumetric};

const char* name(StylingModel model);
const char* name(Minimiser minimiser);
const char* name(ShadingModel model);

// Anjyo's styling extras (Hairstyle Info, repeatable lines). A force field adds an acceleration
// (m/s², like Gravity) to the segments whose start node lies in its region.
struct ForceField {
  enum class Region { kAll, kAbove, kBelow, kSide, kBox };
  glm::dvec3 acceleration{0.0};
  Region region = Region::kAll;
  double level = 0.0;           // kAbove / kBelow: a height, metres
  glm::dvec3 side{0.0};         // kSide: a unit axis (±x or ±z); the region is where p·side > 0
  glm::dvec3 lo{0.0}, hi{0.0};  // kBox
  FileLoc where;
  bool contains(const glm::dvec3& p) const;
};

// A cut: for pores whose azimuth (degrees from the face, +z, toward +x) lies in [azimuthFrom,
// azimuthTo] and whose zenith (degrees from the top) is at most zenithMax, on the head ellipsoid's
// polar coordinates, the hair ends at its first node below `height` (metres).
struct HairCut {
  double azimuthFrom = 0.0, azimuthTo = 0.0, zenithMax = 0.0, height = 0.0;
  FileLoc where;
};

// RootFlow: the direction a follicle leans toward (README, Real heads).
struct RootFlow {
  enum class Kind { kDown, kDirection, kAwayFrom };
  Kind kind = Kind::kDown;
  glm::dvec3 value{0.0, -1.0, 0.0};  // kDirection: a unit vector; kAwayFrom: a point, metres
  // `away-from auto`: the point is the whorl of the head as it is read (fitRootFlow,
  // stages/preflight/scene.h), `resolved` once it is; at() refuses to lean toward a point not yet found.
  bool fitted = false, resolved = false;
  // The direction at a follicle at `root`: down (−y), the fixed vector, or away from the point.
  glm::dvec3 at(const glm::dvec3& root) const;
};

// Hairstyle Info: the mechanics of one hair and the density of the coupe.
struct Hairstyle {
  double visualityStep = 0.0025;    // metres of arc length between output vertices
  double collisionStep = 0.005;     // metres of arc length between collision samples
  int maxIter = 20;                 // Rosenbrock stages at most (bfgs: iterations per coordinate)
  double epsilon = 1.0e-4;          // stop when a stage lowers the energy by less (relative)
  std::vector<double> hairLengths;  // metres, one per Super-Helix element; required
  double hairDensity = 100.0;       // strands per square centimetre of wick
  double hairRadius1 = 35.0e-6;     // metres, semi-axis a of the elliptic cross-section (Table 1)
  double hairRadius2 = 34.5e-6;     // metres, semi-axis b = a·sqrt(1 − e²), e = 0.17 (Table 1)
  double helixRadius = 0.0;         // metres, r_h of the rest helix; 0 = straight (Table 2, smooth)
  double helixStep = 0.0;           // metres, Δ_h, the rise per turn of the rest helix
  double poisson = 0.48;            // σ, dimensionless (Table 1)
  double young = 2.0e9;             // E, pascals (Table 1, Caucasian)
  double massDensity = 1300.0;      // ρ, kilograms per cubic metre (Table 3), key Density
  double gravity = 9.81;            // g, newtons per kilogram (Table 3)
  StylingModel model = StylingModel::kSuperHelix;
  Minimiser minimiser = Minimiser::kRosenbrock;
  double clump = 0.25;     // tip weights v1, v2 drawn in [0, Clump): 0 gathers tips at the nearest guide
  bool strayHairs = true;  // true = the thesis' barycentric assignment (§4.1.4.4)
  uint64_t seed = 0;       // keys every random number; --seed overrides it
  // Follicle inclination: each hair leaves the scalp rootTilt degrees from the normal, toward the
  // RootFlow direction projected onto the scalp (0 = along the normal, the thesis).
  double rootTilt = 0.0;  // degrees
  RootFlow rootFlow;
  // The direction hair leaves the scalp at a follicle at `root` with unit normal `normal`.
  glm::dvec3 growDirection(const glm::dvec3& root, const glm::dvec3& normal) const;
  // Model cantilever (Anjyo et al. 1992):
  int segments = 20;              // equal segments per hair, over the whole of HairLengths
  double flexuralRigidity = 0.0;  // E·I in N·m²; 0 = Young × π a b³/4
  double jointLimit = 180.0;      // degrees: the largest turn between consecutive segments
  int jointLimitFrom = 1;         // the first node (1 = the first after the pore) the limit applies to
  std::vector<ForceField> forces;
  std::vector<HairCut> cuts;

  double totalLength() const;  // metres
};

enum class ShapeKind { kSphere, kEllipsoid, kCuboid };
const char* name(ShapeKind kind);

// One collision body of Collision Info.
struct CollisionShape {
  ShapeKind kind = ShapeKind::kSphere;
  double envelopeGrowth = 0.0;  // metres: envelope growth from the lowest to the highest follicle
  double penalty = 0.0;         // k of the penalty ½k·max(dent + extra, 0)²
  glm::dvec3 centre{0.0};       // metres
  glm::dvec3 halfExtents{0.0};  // metres: radius, semi-axes or half-extents along `axes`
  glm::dmat3 axes{1.0};         // columns: the body's unit axes (orthonormalised on read)
  FileLoc where;                // the config line it came from
  bool fitted = false;          // `auto`: centre and half-extents are fitted to the head (fitCollision)
};

struct Collision {
  std::vector<CollisionShape> shapes;
};

// Which collision shape is the head, the one answer for everything that asks: the cantilever's collision
// avoidance, the centre stray hairs scale about, HeadCentre auto and Anjyo's pseudo-force. The first shape
// fitted to the head (`Ellipsoid v k auto` or `Sphere v k auto`): it is the head by construction. Else the
// first Ellipsoid: the thesis' cranium, as in every bundled config. Else none (null): a Sphere given by
// hand is never the head, since in the thesis and the bundled configs a Sphere is a second body (the face
// in front of the cranium), and a Cuboid is a prop.
const CollisionShape* headShape(const Collision& collision);

// Visuality Info: the hair's reflectance, for every shading model.
struct Visuality {
  glm::dvec3 ambientColor{0.10, 0.10, 0.10};
  glm::dvec3 diffuseColor{0.45, 0.25, 0.00};
  glm::dvec3 specularColor{0.20, 0.20, 0.20};
  double glossiness = 60.0;  // specular exponent p
  // `hairgen shade`: a per-strand coefficient a ~ N(AmbientMean, AmbientDeviation), clamped at 0,
  // multiplies the strand's colour (stored per vertex in the cache).
  double ambientMean = 1.0, ambientDeviation = 0.0;
};

// Render Info (new in hairgen): camera, light and film.
struct RenderSettings {
  glm::ivec2 resolution{640, 640};  // pixels
  // CameraPosition auto (the default when Render Info names none): the render stage frames the hair and
  // the head from the gallery's three-quarter view and places the light relative to it (frameScene).
  bool cameraAuto = true;
  glm::dvec3 cameraPosition{0.32, 0.16, 0.52};  // metres; frames the bundled head from front-right
  glm::dvec3 cameraTarget{0.0, 0.03, 0.0};
  glm::dvec3 cameraUp{0.0, 1.0, 0.0};
  double fieldOfView = 38.0;                // degrees, vertical
  glm::dvec3 lightPosition{0.6, 1.0, 0.8};  // metres
  glm::dvec3 lightColor{1.0, 1.0, 1.0};
  double ambientIntensity = 0.2;
  int samples = 4;                                   // antialiasing sub-pixels per pixel (k² for k×k)
  glm::dvec4 layerSizes{0.002, 0.006, 0.015, 0.04};  // metres: the 4 deep-opacity layer depths
  double strandOpacity = 0.7;                        // opacity of one strand, 0-1
  double strandWidth = 8.0e-5;                       // metres, on-screen diameter of a strand
  ShadingModel shadingModel = ShadingModel::kKajiyaKay;
  glm::dvec3 background{0.18, 0.18, 0.20};
  glm::dvec3 headColor{0.72, 0.55, 0.45};  // Lambert albedo of the head
  // The volumetric model (Petrovic et al. 2005): `hairgen shade` builds the hair's density grid and
  // shell from these, and `ShadingModel volumetric` mixes its shading with Kajiya-Kay by the blend.
  double voxelSize = 0.004;      // metres, the density grid's spacing
  int volumePadding = 3;         // empty voxels around the hair on every side
  double shellDensity = 0.25;    // the shell's density, as a fraction of the density at a typical hair point
  double volumetricBlend = 1.0;  // 0 = Kajiya-Kay, 1 = volumetric
};

// A path named by a config file, with where it was named (for "missing file" errors).
struct PathRef {
  std::filesystem::path path;  // resolved against the naming file's directory
  FileLoc where;
  bool given() const { return !path.empty(); }
};

// Dynamics Info (DESIGN §8): hair in motion, `hairgen simulate`.
enum class DynamicsModel { kAnjyo, kSprings };
const char* name(DynamicsModel model);
inline constexpr DynamicsModel kDynamicsModels[] = {DynamicsModel::kAnjyo, DynamicsModel::kSprings};

// Wind as an acceleration on the hair (m/s², added to gravity) from FRAME on. `linear`: reached from
// the previous key's value by a linear ramp; otherwise the value jumps at FRAME and is held.
struct WindKey {
  double frame = 0.0;
  glm::dvec3 acceleration{0.0};
  bool linear = false;
  FileLoc where;
};

// A pose of the head at FRAME: a translation (metres) and rotations (degrees) about x, then y, then z
// (R = Rz·Ry·Rx), about the head's centre. Between keys the pose moves smoothly (README, Dynamics).
struct HeadKey {
  double frame = 0.0;
  glm::dvec3 translation{0.0};
  glm::dvec3 rotation{0.0};  // degrees
  FileLoc where;
};

struct Dynamics {
  bool given = false;  // the Setup names a Dynamics Info: hairgen simulates
  DynamicsModel model = DynamicsModel::kAnjyo;
  int firstFrame = 1, lastFrame = 48;  // firstFrame is the rest state, the input guides
  double frameRate = 24.0;             // frames per second
  int substeps = 4;                    // integration steps per frame
  double damping = 1.0;                // 1/s: the rate at which motion dies away (air, hair on hair)
  std::vector<WindKey> wind;
  std::vector<HeadKey> headKeys;
  bool headCentreAuto = true;  // the centre of headShape(Collision Info) (else the origin)
  glm::dvec3 headCentre{0.0};  // metres, when not auto
  // Anjyo et al. 1992 §3.2: the inertia of segment i of k is (k/i)^inertiaExponent times that of the
  // segment's mass at the hair's length, and rootInertia times that again for i <= rootSegments (the
  // paper's "rough approximation of friction" near the scalp).
  double inertiaExponent = 1.0;
  double rootInertia = 1.0;
  int rootSegments = 0;
  // §3.2.2, the pseudo-force field: near the head (within pseudoReach of headShape) a force
  // pointing into it (D·F < α|D||F|) is scaled by ε.
  double pseudoAlpha = -0.75, pseudoEpsilon = 0.1, pseudoReach = 0.01;
  // §3.2.3: random turns of up to `fluctuation` radians, drawn once every fluctuationEvery frames.
  double fluctuation = 0.0;
  int fluctuationEvery = 10;
  // The styled shape is held by an angular spring at this frequency (Hz; 0 = no spring), or, when auto,
  // at the hair's own first bending mode, 1.875²·sqrt(E·I/(ρ·A·L⁴))/2π (README, Dynamics).
  bool restFrequencyAuto = true;
  double restFrequency = 0.0;
  // The gravity the hair feels while it moves (N/kg, along −y), when not auto: Hairstyle's Gravity. The
  // rest state is in equilibrium under this one, so a shot without gravity starts still.
  bool gravityAuto = true;
  double gravity = 9.81;
  // Model springs, Petrovic et al. 2006 §5 (libcore/physics/spring_dynamics.h). Stiffnesses, when not
  // auto: from Young, Poisson and the elliptic cross-section (a, b) as the thesis' rod has them.
  bool stretchStiffnessAuto = true;  // E·π a b
  double stretchStiffness = 0.0;     // N: force per unit strain of a segment
  bool bendStiffnessAuto = true;     // E·π a b³/4
  double bendStiffness = 0.0;        // N·m²: E·I
  bool twistStiffnessAuto = true;    // E/(2(1 + σ))·π a b (a² + b²)/4
  double twistStiffness = 0.0;       // N·m²: μ·J
  // §5.1: each frame, every particle loses this fraction of its departure from the smoothed grid
  // velocity at its place (0 = none, 1 = all); the grid's spacing in metres.
  double velocitySmoothing = 0.0;
  double smoothingSpacing = 0.01;
  // §5.2: a hair cache whose density the hair is pushed toward (path relative to the Dynamics Info),
  // the strength (m/s² per point per node of density difference), the grid spacings from coarse to
  // fine (metres), and the fraction of its starting energy at which a spacing hands over to the next.
  PathRef densityTarget;
  double densityStrength = 0.0;
  std::vector<double> densitySpacings{0.02};
  double densityRefine = 0.5;
};

// Setup: which files make up a job.
struct Setup {
  std::filesystem::path file;  // the setup file itself
  bool load = false;           // read the coupe from loadFile instead of growing it
  bool save = false;           // write the coupe to saveFile
  PathRef loadFile, saveFile;
  PathRef hairstyleInfo, collisionInfo, visualityInfo, renderInfo, dynamicsInfo;
  PathRef wickModel, headModel;
  PathRef hairVert, hairFrag, headVert, headFrag;  // optional GLSL overrides
  // MeshUnits and MeshUpAxis: applied to the wick and the head when they are read, so that everything
  // inside hairgen is metres, +y up (README, Real heads).
  UnitConversion meshConversion;
  std::string wickGroup;  // WickGroup: the OBJ group, object or material the follicles grow on; "" = all
};

// A command-line override `--set Section.Key=VALUE`.
struct Override {
  std::string section;  // canonical: Setup, Hairstyle, Collision, Visuality, Render, Dynamics
  std::string key;      // as written
  std::vector<std::string> values;
  std::string text;  // the argument as given
};

// Everything a job reads, after overrides.
struct Config {
  Setup setup;
  Hairstyle hairstyle;
  Collision collision;
  Visuality visuality;
  RenderSettings render;
  Dynamics dynamics;

  // The inputs whose bytes shape the output (the meshes, the shaders, a coupe to load, a density
  // target), each named by its key with a digest of its content (contentDigest), set by loadConfig;
  // one that could not be read is absent. They enter the digest and the paths do not: the same mesh
  // moved is the same configuration, another mesh at the same path is not.
  std::vector<std::pair<std::string, std::string>> inputContent;

  // Canonical text of every value that shapes the output (not the paths), one `Section.Key value` a
  // line, then `Input.Key digest` per input; and its 64-bit FNV-1a digest in hex. Two configs with
  // equal digests give equal output.
  std::string canonicalText() const;
  std::string digest() const;
};

}  // namespace hairgen
