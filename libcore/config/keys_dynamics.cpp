// The keys of Dynamics Info (the models of hair in motion, wind and head keys), declared once;
// keys.cpp makes the section from them, key_helpers.h holds what the section files share.
#include "libcore/config/key_helpers.h"

namespace hairgen::keydecl {

namespace {

// A whole frame number (a key may name any frame, before or after the shot).
double frameOf(const SectionReader& r, const ConfigLine& line) {
  double frame = r.checkReal(line, 0, Range::closed(-1e6, 1e6), "frame");
  if (frame != std::floor(frame)) throw r.error(line, "the frame must be a whole number");
  return frame;
}

Key<Dynamics> framesKey() {
  return customKey<Dynamics>(
      {"Frames", "", "the first frame (the rest state, the input guides) and the last"}, "first last",
      "whole numbers, first < last",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Frames");
        if (!line) return;
        if (line->values.size() != 2) throw r.error(*line, "Frames takes the first and the last frame");
        const double first = frameOf(r, *line),
                     last = r.checkReal(*line, 1, Range::closed(-1e6, 1e6), "last");
        if (last != std::floor(last) || !(last > first))
          throw r.error(*line, "the last frame must be a whole number after the first");
        d.firstFrame = int(first);
        d.lastFrame = int(last);
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{std::to_string(d.firstFrame) + " " + std::to_string(d.lastFrame)};
      });
}

Key<Dynamics> windKey() {
  return repeatable(customKey<Dynamics>(
      {"Wind", "m/s²", "an acceleration on the hair from FRAME on; linear: ramped from the previous key"},
      "FRAME ax ay az [hold | linear]", "",
      [](SectionReader& r, Dynamics& d) {
        for (const ConfigLine* line : r.lines("Wind")) {
          if (line->values.size() != 4 && line->values.size() != 5)
            throw r.error(*line, "Wind takes FRAME ax ay az and, optionally, hold or linear");
          WindKey w;
          w.frame = frameOf(r, *line);
          for (int i = 0; i < 3; ++i)
            w.acceleration[i] = r.checkReal(*line, 1 + i, Range::closed(-1e4, 1e4), "acceleration");
          if (line->values.size() == 5) {
            const std::string mode = toLower(line->values[4]);
            if (mode != "hold" && mode != "linear")
              throw r.error(*line, "'" + line->values[4] + "' is not hold or linear");
            w.linear = mode == "linear";
          }
          w.where = line->where;
          d.wind.push_back(w);
        }
        std::stable_sort(d.wind.begin(), d.wind.end(),
                         [](const WindKey& a, const WindKey& b) { return a.frame < b.frame; });
        for (size_t i = 1; i < d.wind.size(); ++i)
          if (d.wind[i].frame == d.wind[i - 1].frame)
            throw InputError(d.wind[i].where, "a second Wind key at frame " + formatReal(d.wind[i].frame) +
                                                  " (the first is at " + d.wind[i - 1].where.str() + ")");
      },
      [](const Dynamics& d) {
        std::vector<std::string> lines;
        for (const WindKey& w : d.wind)
          lines.push_back(formatReal(w.frame) + " " + join(w.acceleration) +
                          (w.linear ? " linear" : " hold"));
        return lines;
      }));
}

Key<Dynamics> headKeyKey() {
  return repeatable(customKey<Dynamics>(
      {"HeadKey", "m, degrees",
       "the head's pose at FRAME: a translation, and rotations about x, y, z (in that order) about its "
       "centre"},
      "FRAME tx ty tz rx ry rz", "",
      [](SectionReader& r, Dynamics& d) {
        for (const ConfigLine* line : r.lines("HeadKey")) {
          if (line->values.size() != 7) throw r.error(*line, "HeadKey takes FRAME tx ty tz rx ry rz");
          HeadKey k;
          k.frame = frameOf(r, *line);
          for (int i = 0; i < 3; ++i)
            k.translation[i] = r.checkReal(*line, 1 + i, Range::closed(-1e4, 1e4), "translation");
          for (int i = 0; i < 3; ++i)
            k.rotation[i] = r.checkReal(*line, 4 + i, Range::closed(-36000, 36000), "rotation");
          k.where = line->where;
          d.headKeys.push_back(k);
        }
        std::stable_sort(d.headKeys.begin(), d.headKeys.end(),
                         [](const HeadKey& a, const HeadKey& b) { return a.frame < b.frame; });
        for (size_t i = 1; i < d.headKeys.size(); ++i)
          if (d.headKeys[i].frame == d.headKeys[i - 1].frame)
            throw InputError(d.headKeys[i].where, "a second HeadKey at frame " +
                                                      formatReal(d.headKeys[i].frame) + " (the first is at " +
                                                      d.headKeys[i - 1].where.str() + ")");
      },
      [](const Dynamics& d) {
        std::vector<std::string> lines;
        for (const HeadKey& k : d.headKeys)
          lines.push_back(formatReal(k.frame) + " " + join(k.translation) + " " + join(k.rotation));
        return lines;
      }));
}

Key<Dynamics> headCentreKey() {
  return customKey<Dynamics>(
      {"HeadCentre", "m",
       "the point the head turns about; auto = the head shape's centre (docs/configs.md; else the origin)"},
      "auto | x y z", "",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("HeadCentre");
        if (!line) return;
        if (line->values.size() == 1 && toLower(line->values[0]) == "auto") return;
        if (line->values.size() != 3) throw r.error(*line, "HeadCentre takes auto or x y z");
        d.headCentreAuto = false;
        for (int i = 0; i < 3; ++i)
          d.headCentre[i] = r.checkReal(*line, i, Range::closed(-1e4, 1e4), "centre");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{d.headCentreAuto ? std::string("auto") : join(d.headCentre)};
      });
}

Key<Dynamics> inertiaKey() {
  return customKey<Dynamics>(
      {"Inertia", "",
       "segment i of k has (k/i)^p the inertia of its mass at the hair's length, times f for the "
       "first n "
       "segments"},
      "p [f n]", "p in [0, 4], f > 0, n >= 0",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Inertia");
        if (!line) return;
        if (line->values.size() != 1 && line->values.size() != 3)
          throw r.error(*line,
                        "Inertia takes the exponent p and, optionally, a factor f for the first n segments");
        d.inertiaExponent = r.checkReal(*line, 0, Range::closed(0.0, 4.0), "exponent");
        if (line->values.size() == 3) {
          d.rootInertia = r.checkReal(*line, 1, {0.0, 1e6, true, false}, "factor");
          const double n = r.checkReal(*line, 2, Range::closed(0.0, 100000.0), "segments");
          if (n != std::floor(n)) throw r.error(*line, "the number of segments must be a whole number");
          d.rootSegments = int(n);
        }
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.inertiaExponent) + " " + formatReal(d.rootInertia) +
                                        " " + std::to_string(d.rootSegments)};
      });
}

Key<Dynamics> pseudoForceKey() {
  return customKey<Dynamics>(
      {"PseudoForce", "-, -, m",
       "within reach of the head shape, a force with D·F < α|D||F| (into the head) is scaled by "
       "ε"},
      "alpha epsilon reach", "α in [-1, 1], ε in [0, 1], reach >= 0",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("PseudoForce");
        if (!line) return;
        if (line->values.size() != 3) throw r.error(*line, "PseudoForce takes alpha epsilon reach");
        d.pseudoAlpha = r.checkReal(*line, 0, Range::closed(-1.0, 1.0), "alpha");
        d.pseudoEpsilon = r.checkReal(*line, 1, Range::closed(0.0, 1.0), "epsilon");
        d.pseudoReach = r.checkReal(*line, 2, Range::closed(0.0, 10.0), "reach");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.pseudoAlpha) + " " + formatReal(d.pseudoEpsilon) + " " +
                                        formatReal(d.pseudoReach)};
      });
}

Key<Dynamics> fluctuationKey() {
  return customKey<Dynamics>(
      {"Fluctuation", "radians, frames",
       "random turns of each segment up to the amplitude (the most at the tip), drawn once every N "
       "frames"},
      "amplitude N", "amplitude in [0, 1], N >= 1",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("Fluctuation");
        if (!line) return;
        if (line->values.size() != 2)
          throw r.error(*line, "Fluctuation takes an amplitude and every how many frames");
        d.fluctuation = r.checkReal(*line, 0, Range::closed(0.0, 1.0), "amplitude");
        const double n = r.checkReal(*line, 1, Range::closed(1.0, 1e6), "frames");
        if (n != std::floor(n)) throw r.error(*line, "the number of frames must be a whole number");
        d.fluctuationEvery = int(n);
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{formatReal(d.fluctuation) + " " + std::to_string(d.fluctuationEvery)};
      });
}

Key<Dynamics> restFrequencyKey() {
  return customKey<Dynamics>(
      {"RestFrequency", "Hz",
       "the angular spring that holds the styled shape (0 = none); auto = each segment's stiffness in "
       "the elastica of the hair hanging under its weight (without gravity, its first bending mode)"},
      "auto | Hz", "[0, 1000]",
      [](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line("RestFrequency");
        if (!line) return;
        if (line->values.size() != 1) throw r.error(*line, "RestFrequency takes auto or a frequency in Hz");
        if (toLower(line->values[0]) == "auto") return;
        d.restFrequencyAuto = false;
        d.restFrequency = r.checkReal(*line, 0, Range::closed(0.0, 1000.0), "frequency");
      },
      [](const Dynamics& d) {
        return std::vector<std::string>{d.restFrequencyAuto ? std::string("auto")
                                                            : formatReal(d.restFrequency)};
      });
}

// A value that defaults to one computed from other keys: `auto`, or a number in `range`.
Key<Dynamics> autoRealKey(KeyText t, std::string what, bool Dynamics::*isAuto, double Dynamics::*member,
                          Range range) {
  const std::string name = t.name;
  return customKey<Dynamics>(
      t, "auto | " + what, range.describe(),
      [=](SectionReader& r, Dynamics& d) {
        const ConfigLine* line = r.line(name);
        if (!line) return;
        if (line->values.size() != 1) throw r.error(*line, name + " takes auto or a number");
        if (toLower(line->values[0]) == "auto") return;
        d.*isAuto = false;
        d.*member = r.checkReal(*line, 0, range, what);
      },
      [=](const Dynamics& d) {
        return std::vector<std::string>{d.*isAuto ? std::string("auto") : formatReal(d.*member)};
      });
}

Key<Dynamics> densitySpacingsKey() {
  return customKey<Dynamics>(
      {"DensitySpacings", "m",
       "the density grids' spacings, coarse to fine; the next takes over when the energy at this "
       "one falls to DensityRefine of its start"},
      "h1 [h2 ...]", "[0.0001, 1], not increasing",
      [](SectionReader& r, Dynamics& d) {
        if (!r.has("DensitySpacings")) return;
        // From a tenth of a millimetre (a few hair widths; finer grids resolve single hairs, not a
        // density) to a metre (a whole head in one cell). Their memory is simulate's estimate's.
        d.densitySpacings = r.realList("DensitySpacings", Range::closed(1e-4, 1.0));
        for (size_t i = 1; i < d.densitySpacings.size(); ++i)
          if (d.densitySpacings[i] > d.densitySpacings[i - 1])
            throw InputError(r.where("DensitySpacings"),
                             "DensitySpacings go from coarse to fine: " + formatReal(d.densitySpacings[i]) +
                                 " follows the finer " + formatReal(d.densitySpacings[i - 1]));
      },
      [](const Dynamics& d) {
        std::string out;
        for (double h : d.densitySpacings) out += (out.empty() ? "" : " ") + formatReal(h);
        return std::vector<std::string>{out};
      });
}

// The keys only one model reads (declared with `only`): naming one for the other model is an error (a key
// that is read is used).
void checkModelKeys(SectionReader& r, const Dynamics& d) {
  for (const KeySpec& key : dynamicsKeys().spec.keys) {
    if (key.models.empty() || !r.has(key.name) ||
        std::find(key.models.begin(), key.models.end(), name(d.model)) != key.models.end())
      continue;
    std::string models;
    for (const std::string& model : key.models) models += (models.empty() ? "" : " or ") + model;
    throw InputError(r.where(key.name), key.name + " is a key of Model " + models +
                                            ", and this Dynamics Info is Model " + name(d.model) +
                                            "; remove it or change the Model");
  }
  for (const char* key : {"DensitySpacings", "DensityRefine"})
    if (r.has(key) && !d.densityTarget.given())
      throw InputError(r.where(key),
                       std::string(key) +
                           " sets up the density grids of a DensityTarget, and none is named; add "
                           "`DensityTarget FILE` (a hair cache) or remove it");
  if (r.has("SmoothingSpacing") && !(d.velocitySmoothing > 0.0))
    throw InputError(r.where("SmoothingSpacing"),
                     "SmoothingSpacing is the grid of VelocitySmoothing, which is 0; set VelocitySmoothing "
                     "above 0 or remove it");
  if (d.densityStrength > 0.0 && !d.densityTarget.given())
    throw InputError(r.where("DensityStrength"),
                     "DensityStrength pushes the hair toward a DensityTarget, and none is named; add "
                     "`DensityTarget FILE` (a hair cache)");
}

// A Dynamics key that only `model` reads.
Key<Dynamics> only(DynamicsModel model, Key<Dynamics> key) {
  return onlyFor<Dynamics>({name(model)}, std::move(key));
}

}  // namespace

Section<Dynamics> makeDynamics() {
  using D = Dynamics;
  return makeSection<D>(
      "Dynamics", "Dynamics Info", "DynamicsInfo",
      {choiceKey<D, DynamicsModel>({"Model", "", "anjyo (Anjyo et al. §3) or springs (Petrovic et al. §5)"},
                                   &D::model, {std::begin(kDynamicsModels), std::end(kDynamicsModels)}),
       framesKey(),
       // From a frame a second (a time-lapse) to 10000 (high-speed footage): a step of more than a second
       // is no shot's, and 1e-20 frames/s overflows the step.
       realKey<D>({"FrameRate", "frames/s", "frames per second"}, &D::frameRate, Range::closed(1.0, 10000.0)),
       integerKey<D>({"Substeps", "", "integration steps per frame"}, &D::substeps, 1, 1000),
       realKey<D>({"Damping", "1/s", "the rate at which motion dies away (air, hair on hair)"}, &D::damping,
                  Range::closed(0.0, 1000.0)),
       windKey(), headKeyKey(), headCentreKey(),
       only(DynamicsModel::kSprings,
            autoRealKey({"Gravity", "N/kg",
                         "the gravity the moving hair feels, along -y; auto = Hairstyle's Gravity"},
                        "N/kg", &D::gravityAuto, &D::gravity, Range::closed(0.0, 1000.0))),
       only(DynamicsModel::kAnjyo, inertiaKey()), only(DynamicsModel::kAnjyo, pseudoForceKey()),
       only(DynamicsModel::kAnjyo, fluctuationKey()), only(DynamicsModel::kAnjyo, restFrequencyKey()),
       only(DynamicsModel::kSprings,
            autoRealKey({"StretchStiffness", "N",
                         "a segment's force per unit strain, E·A; auto = Young × π a b (effectively "
                         "inextensible)"},
                        "N", &D::stretchStiffnessAuto, &D::stretchStiffness, Range::positive())),
       only(DynamicsModel::kSprings,
            autoRealKey({"BendStiffness", "N·m²", "E·I; auto = Young × π a b³/4"}, "N·m²",
                        &D::bendStiffnessAuto, &D::bendStiffness, Range::nonNegative())),
       only(DynamicsModel::kSprings,
            autoRealKey({"TwistStiffness", "N·m²", "μ·J; auto = Young/(2(1 + Poisson)) × π a b (a² + b²)/4"},
                        "N·m²", &D::twistStiffnessAuto, &D::twistStiffness, Range::nonNegative())),
       only(DynamicsModel::kSprings,
            realKey<D>({"VelocitySmoothing", "",
                        "the fraction of each particle's departure from the smoothed grid velocity "
                        "removed per frame (Petrovic et al. §5.1)"},
                       &D::velocitySmoothing, Range::closed(0.0, 1.0))),
       only(DynamicsModel::kSprings, realKey<D>({"SmoothingSpacing", "m", "the velocity grid's spacing"},
                                                &D::smoothingSpacing, {0.0, 10.0, true, false})),
       only(DynamicsModel::kSprings,
            pathKey<D>({"DensityTarget", "",
                        "a hair cache whose density the hair is pushed toward (Petrovic et al. §5.2)"},
                       &D::densityTarget)),
       only(DynamicsModel::kSprings,
            realKey<D>({"DensityStrength", "m/s²",
                        "the density force (Petrovic et al. §5.2) as a point's acceleration where the "
                        "density differs from the target's by its mean from one node to the next; 0 = none"},
                       &D::densityStrength, Range::closed(0.0, 1e9))),
       only(DynamicsModel::kSprings, densitySpacingsKey()),
       only(DynamicsModel::kSprings,
            realKey<D>({"DensityRefine", "",
                        "a density spacing hands over to the next finer one when its energy falls "
                        "to this fraction of its start"},
                       &D::densityRefine, {0.0, 1.0, true, false}))},
      checkModelKeys);
}

}  // namespace hairgen::keydecl
