// The keys of Hairstyle Info (the styling models' parameters, forces and cuts), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

namespace {

ForceField readForce(const SectionReader& r, const ConfigLine& line) {
  auto bad = [&](const std::string& why) {
    return r.error(
        line, "Force " + why +
                  "; expected ax ay az all | above Y | below Y | side +x|-x|+z|-z | box x0 y0 z0 x1 y1 z1");
  };
  if (line.values.size() < 4) throw bad("needs an acceleration and a region");
  ForceField f;
  f.where = line.where;
  for (int i = 0; i < 3; ++i)
    f.acceleration[i] = r.checkReal(line, i, Range::closed(-1e4, 1e4), "acceleration");
  const std::string region = toLower(line.values[3]);
  const size_t extra = line.values.size() - 4;
  if (region == "all" && extra == 0) {
    f.region = ForceField::Region::kAll;
  } else if ((region == "above" || region == "below") && extra == 1) {
    f.region = region == "above" ? ForceField::Region::kAbove : ForceField::Region::kBelow;
    f.level = r.checkReal(line, 4, {}, "height");
  } else if (region == "side" && extra == 1) {
    const std::string& s = line.values[4];
    f.region = ForceField::Region::kSide;
    if (s == "+x")
      f.side = {1, 0, 0};
    else if (s == "-x")
      f.side = {-1, 0, 0};
    else if (s == "+z")
      f.side = {0, 0, 1};
    else if (s == "-z")
      f.side = {0, 0, -1};
    else
      throw bad("side '" + s + "' is not +x, -x, +z or -z");
  } else if (region == "box" && extra == 6) {
    f.region = ForceField::Region::kBox;
    for (int i = 0; i < 3; ++i) f.lo[i] = r.checkReal(line, 4 + i, {}, "box corner");
    for (int i = 0; i < 3; ++i) f.hi[i] = r.checkReal(line, 7 + i, {}, "box corner");
  } else {
    throw bad("region '" + line.values[3] + "' with " + std::to_string(extra) + " values is not understood");
  }
  return f;
}

Key<Hairstyle> hairLengthsKey() {
  return required(customKey<Hairstyle>(
      {"HairLengths",
       "m",
       "one length per Super-Helix element (at most 256), e.g. 0.04 0.04 0.04 0.04",
       {"HairLength"}},
      "real ...", "(0, 10]",
      [](SectionReader& r, Hairstyle& h) {
        h.hairLengths = r.realList("HairLengths", {0.0, 10.0, true, false});
        if (h.hairLengths.size() > 256)
          throw InputError(r.where("HairLengths"), "at most 256 Super-Helix elements are supported, found " +
                                                       std::to_string(h.hairLengths.size()));
      },
      [](const Hairstyle& h) {
        std::string out;
        for (double l : h.hairLengths) out += (out.empty() ? "" : " ") + formatReal(l);
        return std::vector<std::string>{out};
      }));
}

Key<Hairstyle> jointLimitKey() {
  return customKey<Hairstyle>(
      {"JointAngleLimit", "degrees",
       "cantilever: the largest turn between consecutive segments, from node n on (180 = none)"},
      "degrees [n]", "[0, 180], n >= 1",
      [](SectionReader& r, Hairstyle& h) {
        if (!r.has("JointAngleLimit")) return;
        const ConfigLine& line = *r.line("JointAngleLimit");
        if (line.values.size() > 2)
          throw r.error(line, "JointAngleLimit takes degrees and, optionally, the first node it applies to");
        h.jointLimit = r.checkReal(line, 0, Range::closed(0.0, 180.0), "degrees");
        if (line.values.size() == 2) {
          double from = r.checkReal(line, 1, Range::closed(1.0, 100000.0), "first node");
          if (from != std::floor(from)) throw r.error(line, "the first node must be a whole number");
          h.jointLimitFrom = static_cast<int>(from);
        }
      },
      [](const Hairstyle& h) {
        return std::vector<std::string>{formatReal(h.jointLimit) + " " + std::to_string(h.jointLimitFrom)};
      });
}

Key<Hairstyle> forceKey() {
  return repeatable(customKey<Hairstyle>(
      {"Force", "m/s²", "cantilever: an acceleration added to gravity on the segments starting in a region"},
      "ax ay az all | above Y | below Y | side +x|-x|+z|-z | box x0 y0 z0 x1 y1 z1", "",
      [](SectionReader& r, Hairstyle& h) {
        for (const ConfigLine* line : r.lines("Force")) h.forces.push_back(readForce(r, *line));
      },
      [](const Hairstyle& h) {
        std::vector<std::string> lines;
        for (const ForceField& f : h.forces)
          lines.push_back(join(f.acceleration) + " " + std::to_string(int(f.region)) + " " +
                          formatReal(f.level) + " " + join(f.side) + " " + join(f.lo) + " " + join(f.hi));
        return lines;
      }));
}

Key<Hairstyle> cutKey() {
  return repeatable(customKey<Hairstyle>(
      {"Cut", "degrees, m",
       "cantilever: pores with azimuth in [from, to] (from the face toward +x) and zenith <= max end at "
       "their last node above the height"},
      "azimuthFrom azimuthTo zenithMax height", "",
      [](SectionReader& r, Hairstyle& h) {
        for (const ConfigLine* line : r.lines("Cut")) {
          if (line->values.size() != 4)
            throw r.error(*line, "Cut takes azimuthFrom azimuthTo zenithMax height, found " +
                                     std::to_string(line->values.size()) + " values");
          HairCut c;
          c.azimuthFrom = r.checkReal(*line, 0, Range::closed(-360.0, 360.0), "azimuth");
          c.azimuthTo = r.checkReal(*line, 1, Range::closed(-360.0, 360.0), "azimuth");
          c.zenithMax = r.checkReal(*line, 2, Range::closed(0.0, 180.0), "zenith");
          c.height = r.checkReal(*line, 3, {}, "height");
          c.where = line->where;
          h.cuts.push_back(c);
        }
      },
      [](const Hairstyle& h) {
        std::vector<std::string> lines;
        for (const HairCut& c : h.cuts)
          lines.push_back(join({c.azimuthFrom, c.azimuthTo, c.zenithMax, c.height}));
        return lines;
      }));
}

// RootTilt and RootFlow enter the digest only when they lean the hair, so that the digest of a
// Hairstyle Info written before them does not change.
Key<Hairstyle> rootTiltKey() {
  return customKey<Hairstyle>(
      {"RootTilt", "degrees", "each hair leaves the scalp this far from the normal, toward RootFlow"},
      "degrees", "[0, 89]",
      [](SectionReader& r, Hairstyle& h) { h.rootTilt = r.real("RootTilt", 0.0, Range::closed(0.0, 89.0)); },
      [](const Hairstyle& h) {
        return h.rootTilt > 0.0 ? std::vector<std::string>{formatReal(h.rootTilt)}
                                : std::vector<std::string>{};
      });
}

Key<Hairstyle> rootFlowKey() {
  return customKey<Hairstyle>(
      {"RootFlow", "m",
       "the direction follicles lean toward: down, a vector x y z, away-from x y z (a point, e.g. the "
       "whorl), or away-from auto (the whorl of the head read, docs/real-heads.md)"},
      "down | x y z | away-from x y z | away-from auto", "",
      [](SectionReader& r, Hairstyle& h) {
        const ConfigLine* line = r.line("RootFlow");
        if (!line) return;
        const std::vector<std::string>& v = line->values;
        const std::string first = toLower(v[0]);
        if (first == "down" && v.size() == 1) return;
        const bool away = first == "away-from";
        if (away && v.size() == 2 && toLower(v[1]) == "auto") {
          h.rootFlow.kind = RootFlow::Kind::kAwayFrom;
          h.rootFlow.fitted = true;
          return;
        }
        if (v.size() != (away ? 4u : 3u))
          throw r.error(*line, "RootFlow takes down, a direction x y z, away-from x y z or away-from auto");
        glm::dvec3 value;
        for (int i = 0; i < 3; ++i)
          value[i] = r.checkReal(*line, away + i, Range::closed(-1e4, 1e4), "RootFlow");
        if (!away && glm::length(value) < 1e-9) throw r.error(*line, "RootFlow's direction is zero");
        h.rootFlow.kind = away ? RootFlow::Kind::kAwayFrom : RootFlow::Kind::kDirection;
        h.rootFlow.value = away ? value : glm::normalize(value);
      },
      [](const Hairstyle& h) {
        if (h.rootTilt <= 0.0 || h.rootFlow.kind == RootFlow::Kind::kDown) return std::vector<std::string>{};
        if (h.rootFlow.fitted)
          return std::vector<std::string>{"away-from auto"};  // the head's digest decides
        return std::vector<std::string>{
            std::string(h.rootFlow.kind == RootFlow::Kind::kAwayFrom ? "away-from " : "") +
            join(h.rootFlow.value)};
      });
}

}  // namespace

Section<Hairstyle> makeHairstyle() {
  using H = Hairstyle;
  const Range aboveZeroToOne{0.0, 1.0, true, false};
  return makeSection<H>(
      "Hairstyle", "Hairstyle Info", "HairstyleInfo",
      {realKey<H>({"VisualityStep", "m", "arc length between output vertices"}, &H::visualityStep,
                  aboveZeroToOne),
       realKey<H>({"CollisionStep", "m", "arc length between collision samples"}, &H::collisionStep,
                  aboveZeroToOne),
       choiceKey<H, Minimiser>({"Minimiser", "",
                                "rosenbrock (the thesis' direct search) or bfgs (quasi-Newton on the "
                                "energy's analytic gradient)"},
                               &H::minimiser, {Minimiser::kRosenbrock, Minimiser::kBfgs}),
       integerKey<H>({"MaxIter", "", "Rosenbrock stages at most; bfgs: iterations at most, per coordinate"},
                     &H::maxIter, 1, 1000000),
       realKey<H>({"Epsilon", "",
                   "relative energy change between stages that ends minimisation (bfgs: the predicted and "
                   "the last decrease both below Epsilon/100)"},
                  &H::epsilon, Range::positive()),
       hairLengthsKey(),
       realKey<H>({"HairDensity", "strands/cm²", "strands per square centimetre of wick"}, &H::hairDensity,
                  Range::nonNegative()),
       realKey<H>({"HairRadius1", "m", "semi-axis a of the elliptic cross-section"}, &H::hairRadius1,
                  {0.0, 0.01, true, false}),
       realKey<H>({"HairRadius2", "m", "semi-axis b of the elliptic cross-section"}, &H::hairRadius2,
                  {0.0, 0.01, true, false}),
       realKey<H>({"HelixRadius", "m", "radius of the rest helix; 0 = straight"}, &H::helixRadius,
                  Range::closed(0.0, 1000.0)),
       realKey<H>({"HelixStep", "m", "rise per turn of the rest helix"}, &H::helixStep,
                  Range::closed(-1000.0, 1000.0)),
       realKey<H>({"Poisson", "", "Poisson's ratio σ"}, &H::poisson, {-1.0, 0.5, true, false}),
       realKey<H>({"Young", "Pa", "Young's modulus E"}, &H::young, Range::positive()),
       realKey<H>({"Density", "kg/m³", "mass density ρ of the hair fibre"}, &H::massDensity,
                  Range::nonNegative()),
       realKey<H>({"Gravity", "N/kg", "gravitational acceleration g, pulling along -y"}, &H::gravity,
                  Range::closed(0.0, 1000.0)),
       choiceKey<H, StylingModel>(
           {"Model", "", "the styling model: Super-Helix guides or Anjyo's cantilever"}, &H::model,
           {StylingModel::kSuperHelix, StylingModel::kCantilever}),
       realKey<H>({"Clump", "", "tip weights drawn in [0, Clump): 0 gathers tips at the nearest guide"},
                  &H::clump, Range::closed(0.0, 1.0)),
       boolKey<H>({"StrayHairs", "", "true = the thesis' barycentric assignment (§4.1.4.4)"}, &H::strayHairs),
       unsignedKey<H>({"Seed", "", "keys every random number; --seed overrides it"}, &H::seed),
       rootTiltKey(),
       rootFlowKey(),
       integerKey<H>({"Segments", "", "cantilever: equal segments per hair"}, &H::segments, 1, 65535),
       realKey<H>({"FlexuralRigidity", "N·m²", "cantilever: E·I; 0 = Young × π a b³/4"}, &H::flexuralRigidity,
                  Range::nonNegative()),
       jointLimitKey(),
       forceKey(),
       cutKey()});
}

}  // namespace hairgen::keydecl
