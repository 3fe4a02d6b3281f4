#include "libcore/config/config.h"

#include <cmath>

#include "libcore/util/file_util.h"
#include "libcore/util/text.h"

namespace hairgen {
namespace {

KeySpec key(std::string name, std::string hint, std::vector<std::string> aliases = {},
            bool repeatable = false) {
  return KeySpec{std::move(name), std::move(aliases), std::move(hint), repeatable};
}

std::vector<SectionSpec> makeSections() {
  return {
      {"Setup",
       "Setup",
       {key("Load", "true or false: read the coupe from LoadFile instead of growing it"),
        key("Save", "true or false: write the coupe to SaveFile"),
        key("LoadFile", "path of a .hair/.gltf/.glb coupe", {"LoadPath"}),
        key("SaveFile", "path of a .hair/.gltf/.glb coupe", {"SavePath"}),
        key("HairstyleInfo", "path of the Hairstyle Info file"),
        key("CollisionInfo", "path of the Collision Info file"),
        key("VisualityInfo", "path of the Visuality Info file"),
        key("RenderInfo", "path of the Render Info file"),
        key("WickModel", "path of the wick OBJ (every vertex a follicle)", {"HairModel"}),
        key("HeadModel", "path of the head OBJ"),
        key("HairVert", "path of a GLSL vertex shader for the hair"),
        key("HairFrag", "path of a GLSL fragment shader for the hair"),
        key("HeadVert", "path of a GLSL vertex shader for the head"),
        key("HeadFrag", "path of a GLSL fragment shader for the head")}},
      {"Hairstyle",
       "Hairstyle Info",
       {key("VisualityStep", "metres between output vertices, e.g. 0.0025"),
        key("CollisionStep", "metres between collision samples, e.g. 0.005"),
        key("MaxIter", "Rosenbrock stages at most, an integer >= 1, e.g. 20"),
        key("Epsilon", "relative energy change that ends minimisation, e.g. 0.0001"),
        key("HairLengths", "metres, one per Super-Helix element, e.g. 0.04 0.04 0.04 0.04", {"HairLength"}),
        key("HairDensity", "strands per square centimetre, e.g. 80"),
        key("HairRadius1", "metres, semi-axis a of the cross-section, e.g. 0.000035"),
        key("HairRadius2", "metres, semi-axis b of the cross-section, e.g. 0.000050"),
        key("HelixRadius", "metres, radius of the rest helix (0 = straight), e.g. 0.025"),
        key("HelixStep", "metres, rise per turn of the rest helix, e.g. 0.025"),
        key("Poisson", "Poisson's ratio in (-1, 0.5], e.g. 0.48"),
        key("Young", "Young's modulus in pascals, e.g. 2e9"),
        key("Density", "kilograms per cubic metre, e.g. 1300"),
        key("Gravity", "newtons per kilogram, e.g. 9.81"),
        key("Model", "superhelix or cantilever"),
        key("Clump", "0 to 1, e.g. 0.25"),
        key("StrayHairs", "true or false"),
        key("Seed", "a non-negative integer"),
        key("Segments", "cantilever: equal segments per hair, e.g. 20"),
        key("FlexuralRigidity", "cantilever: E*I in N m^2 (0 = from Young and the radii)"),
        key("JointAngleLimit", "cantilever: degrees [first node], e.g. 15 5"),
        key("Force", "ax ay az all | above Y | below Y | side +x|-x|+z|-z | box x0 y0 z0 x1 y1 z1", {}, true),
        key("Cut", "azimuthFrom azimuthTo zenithMax height (degrees, degrees, degrees, metres)", {}, true)}},
      {"Collision",
       "Collision Info",
       {key("Sphere", "volume penalty cx cy cz r", {}, true),
        key("Ellipsoid", "volume penalty cx cy cz a b c ux uy uz vx vy vz wx wy wz", {"Elipsoid"}, true),
        key("Cuboid", "volume penalty cx cy cz a b c ux uy uz vx vy vz wx wy wz", {}, true)}},
      {"Visuality",
       "Visuality Info",
       {key("AmbientColor", "r g b, e.g. 0.10 0.10 0.10"), key("DiffuseColor", "r g b, e.g. 0.45 0.25 0.00"),
        key("SpecularColor", "r g b, e.g. 0.20 0.20 0.20"), key("Glossiness", "specular exponent, e.g. 60"),
        key("AmbientMean", "hairgen shade: mean of the per-strand coefficient, e.g. 1"),
        key("AmbientDeviation", "hairgen shade: its standard deviation, e.g. 0.15")}},
      {"Render",
       "Render Info",
       {key("Resolution", "width height in pixels, e.g. 640 640"), key("CameraPosition", "x y z in metres"),
        key("CameraTarget", "x y z in metres"), key("CameraUp", "x y z"),
        key("FieldOfView", "vertical, degrees in (0, 180), e.g. 38"), key("LightPosition", "x y z in metres"),
        key("LightColor", "r g b"), key("AmbientIntensity", ">= 0, e.g. 0.2"),
        key("Samples", "antialiasing samples per pixel, 1 to 64"),
        key("LayerSizes", "four depths in metres, e.g. 0.002 0.006 0.015 0.04"),
        key("StrandOpacity", "0 to 1, e.g. 0.7"), key("StrandWidth", "metres, e.g. 0.00008"),
        key("ShadingModel", "kajiya-kay, thesis, anjyo or volumetric"), key("Background", "r g b"),
        key("HeadColor", "r g b, the head's albedo"),
        key("VoxelSize", "hairgen shade: metres between density grid nodes, e.g. 0.004"),
        key("VolumePadding", "hairgen shade: empty voxels around the hair, e.g. 3"),
        key("ShellDensity",
            "hairgen shade: the shell's density as a fraction of a typical hair point's, e.g. 0.25"),
        key("VolumetricBlend", "0 (Kajiya-Kay) to 1 (volumetric), e.g. 1")}},
  };
}

std::vector<std::string> spellings(const SectionSpec& section) {
  std::vector<std::string> names;
  for (const KeySpec& k : section.keys) names.push_back(k.name);
  return names;
}

// The canonical name of `written` in `section`, or "" if the section has no such key.
std::string canonicalKey(const SectionSpec& section, std::string_view written) {
  std::string lower = toLower(written);
  for (const KeySpec& k : section.keys) {
    if (toLower(k.name) == lower) return k.name;
    for (const std::string& alias : k.aliases)
      if (toLower(alias) == lower) return k.name;
  }
  return {};
}

// "did you mean ...", or "it belongs in ..." when another section knows the key.
std::string unknownKeyHint(const SectionSpec& section, std::string_view written) {
  for (const SectionSpec& other : allSections())
    if (&other != &section && !canonicalKey(other, written).empty())
      return "; '" + canonicalKey(other, written) + "' belongs in " + other.title;
  std::string close = closestMatch(written, spellings(section));
  if (!close.empty()) return "; did you mean '" + close + "'?";
  return "; " + section.title + " knows: " + [&] {
    std::string all;
    for (const KeySpec& k : section.keys) all += (all.empty() ? "" : ", ") + k.name;
    return all;
  }();
}

}  // namespace

const std::vector<SectionSpec>& allSections() {
  static const std::vector<SectionSpec> sections = makeSections();
  return sections;
}

const SectionSpec& sectionSpec(std::string_view name) {
  for (const SectionSpec& s : allSections())
    if (toLower(s.name) == toLower(name)) return s;
  throw InputError("unknown config section '" + std::string(name) + "'");
}

ConfigText parseConfigText(std::string_view text, const std::string& name,
                           const std::filesystem::path& baseDir) {
  ConfigText config{name, baseDir, {}};
  int lineNumber = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    ++lineNumber;
    pos = end + 1;
    FileLoc where{name, lineNumber};

    std::vector<std::string> tokens;
    std::string token;
    bool inToken = false, quoted = false;
    for (size_t i = 0; i < line.size(); ++i) {
      char c = line[i];
      if (quoted) {
        if (c == '"') {
          quoted = false;
        } else {
          token += c;
        }
        continue;
      }
      if (c == '#') break;
      if (c == '"') {
        quoted = inToken = true;
        continue;
      }
      if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        if (inToken) tokens.push_back(std::move(token));
        token.clear();
        inToken = false;
        continue;
      }
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
        throw InputError(where, "control character (byte " + std::to_string(static_cast<unsigned char>(c)) +
                                    ") in a config file; is this a text file?");
      token += c;
      inToken = true;
    }
    if (quoted) throw InputError(where, "unterminated quoted string; close it with \"");
    if (inToken) tokens.push_back(std::move(token));
    if (tokens.empty()) continue;
    ConfigLine parsed{where, tokens.front(), {tokens.begin() + 1, tokens.end()}};
    config.lines.push_back(std::move(parsed));
    if (end == text.size()) break;
  }
  return config;
}

ConfigText readConfigText(const std::filesystem::path& file) {
  return parseConfigText(readFileText(file), file.string(), file.parent_path());
}

Override parseOverride(std::string_view argument) {
  FileLoc where{"--set " + std::string(argument), 0};
  size_t dot = argument.find('.');
  size_t eq = argument.find('=');
  if (dot == std::string_view::npos || eq == std::string_view::npos || dot > eq)
    throw InputError(where, "expected Section.Key=VALUE, e.g. --set Hairstyle.HairDensity=160");
  std::string sectionName(argument.substr(0, dot));
  const SectionSpec* section = nullptr;
  for (const SectionSpec& s : allSections())
    if (toLower(s.name) == toLower(sectionName) || toLower(s.name) + "info" == toLower(sectionName))
      section = &s;
  if (!section) {
    std::vector<std::string> names;
    for (const SectionSpec& s : allSections()) names.push_back(s.name);
    std::string close = closestMatch(sectionName, names);
    throw InputError(where,
                     "unknown section '" + sectionName + "'" +
                         (close.empty() ? "; sections are Setup, Hairstyle, Collision, Visuality, Render"
                                        : "; did you mean '" + close + "'?"));
  }
  std::string keyName(argument.substr(dot + 1, eq - dot - 1));
  if (canonicalKey(*section, keyName).empty())
    throw InputError(
        where, "unknown key '" + keyName + "' in " + section->title + unknownKeyHint(*section, keyName));
  ConfigText parsed = parseConfigText(argument.substr(eq + 1), where.file, std::filesystem::current_path());
  std::vector<std::string> values;
  for (const ConfigLine& line : parsed.lines) {
    values.push_back(line.key);
    values.insert(values.end(), line.values.begin(), line.values.end());
  }
  if (values.empty()) throw InputError(where, "no value after '='");
  return Override{section->name, keyName, values, std::string(argument)};
}

bool Range::contains(double v) const {
  if (openMin ? !(v > min) : !(v >= min)) return false;
  if (openMax ? !(v < max) : !(v <= max)) return false;
  return true;
}

std::string Range::describe() const {
  bool hasMin = min > -1e299, hasMax = max < 1e299;
  if (hasMin && !hasMax) return std::string(openMin ? "> " : ">= ") + formatReal(min);
  if (!hasMin && hasMax) return std::string(openMax ? "< " : "<= ") + formatReal(max);
  return std::string(openMin ? "(" : "[") + formatReal(min) + ", " + formatReal(max) + (openMax ? ")" : "]");
}

SectionReader::SectionReader(ConfigText text, const SectionSpec& spec, const std::vector<Override>& overrides)
    : text_(std::move(text)), section_(spec) {
  for (const Override& o : overrides) {
    if (o.section != section_.name) continue;
    std::string canonical = canonicalKey(section_, o.key);
    ConfigLine line;
    line.where.file = "--set " + o.text;
    line.key = o.key;
    line.values = o.values;
    bool repeatable = this->spec(canonical).repeatable;
    bool replaced = false;
    for (size_t i = 0; i < text_.lines.size();) {
      if (canonicalKey(section_, text_.lines[i].key) != canonical) {
        ++i;
      } else if (repeatable || replaced) {
        text_.lines.erase(text_.lines.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        text_.lines[i] = line;
        replaced = true;
        ++i;
      }
    }
    if (!replaced) text_.lines.push_back(line);
  }
  used_.assign(text_.lines.size(), false);
}

const KeySpec& SectionReader::spec(std::string_view key) const {
  for (const KeySpec& k : section_.keys)
    if (k.name == key) return k;
  throw std::logic_error("SectionReader: key '" + std::string(key) + "' is not in " + section_.title);
}

InputError SectionReader::error(const ConfigLine& line, const std::string& message) const {
  return InputError(line.where, message);
}

bool SectionReader::has(std::string_view key) const {
  for (const ConfigLine& line : text_.lines)
    if (canonicalKey(section_, line.key) == key) return true;
  return false;
}

FileLoc SectionReader::where(std::string_view key) const {
  for (const ConfigLine& line : text_.lines)
    if (canonicalKey(section_, line.key) == key) return line.where;
  return {text_.name, 0};
}

const ConfigLine* SectionReader::single(std::string_view key) {
  spec(key);
  const ConfigLine* found = nullptr;
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (canonicalKey(section_, text_.lines[i].key) != key) continue;
    if (found)
      throw InputError(text_.lines[i].where, "duplicate key '" + std::string(key) + "' (first given at " +
                                                 found->where.str() + "); give it once");
    found = &text_.lines[i];
    used_[i] = true;
  }
  if (found && found->values.empty())
    throw InputError(found->where, "'" + std::string(key) + "' has no value; expected " + spec(key).hint);
  return found;
}

void SectionReader::expectCount(const ConfigLine& line, size_t count) const {
  if (line.values.size() != count)
    throw InputError(line.where, "'" + line.key + "' takes " + std::to_string(count) + " value" +
                                     (count == 1 ? "" : "s") + ", found " +
                                     std::to_string(line.values.size()) + "; expected " +
                                     spec(canonicalKey(section_, line.key)).hint);
}

double SectionReader::checkReal(const ConfigLine& line, size_t index, Range range,
                                std::string_view what) const {
  const std::string& token = line.values.at(index);
  std::optional<double> value = parseReal(token);
  std::string label = what.empty() ? "'" + line.key + "'" : "'" + line.key + "' " + std::string(what);
  if (!value) throw InputError(line.where, label + ": '" + token + "' is not a number");
  if (!std::isfinite(*value)) throw InputError(line.where, label + ": '" + token + "' is not finite");
  if (!range.contains(*value))
    throw InputError(line.where, label + " = " + token + " is out of range; it must be " + range.describe());
  return *value;
}

double SectionReader::real(std::string_view key, std::optional<double> fallback, Range range) {
  const ConfigLine* line = single(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint + ")");
    return *fallback;
  }
  expectCount(*line, 1);
  return checkReal(*line, 0, range, "");
}

int64_t SectionReader::integer(std::string_view key, std::optional<int64_t> fallback, int64_t min,
                               int64_t max) {
  const ConfigLine* line = single(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint + ")");
    return *fallback;
  }
  expectCount(*line, 1);
  std::optional<int64_t> value = parseInt(line->values[0]);
  if (!value)
    throw InputError(line->where, "'" + line->key + "': '" + line->values[0] + "' is not an integer");
  if (*value < min || *value > max)
    throw InputError(line->where, "'" + line->key + "' = " + line->values[0] +
                                      " is out of range; it must be in [" + std::to_string(min) + ", " +
                                      std::to_string(max) + "]");
  return *value;
}

uint64_t SectionReader::unsignedInteger(std::string_view key, uint64_t fallback) {
  const ConfigLine* line = single(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  std::optional<uint64_t> value = parseUInt(line->values[0]);
  if (!value)
    throw InputError(line->where,
                     "'" + line->key + "': '" + line->values[0] + "' is not a non-negative integer");
  return *value;
}

std::vector<double> SectionReader::reals(std::string_view key, size_t count,
                                         std::optional<std::vector<double>> fallback, Range range) {
  const ConfigLine* line = single(key);
  if (!line) {
    if (!fallback)
      throw InputError({text_.name, 0},
                       "missing required key '" + std::string(key) + "' (" + spec(key).hint + ")");
    return *fallback;
  }
  expectCount(*line, count);
  std::vector<double> values;
  for (size_t i = 0; i < count; ++i)
    values.push_back(checkReal(*line, i, range, count > 1 ? "value " + std::to_string(i + 1) : ""));
  return values;
}

std::vector<double> SectionReader::realList(std::string_view key, Range range) {
  const ConfigLine* line = single(key);
  if (!line)
    throw InputError({text_.name, 0},
                     "missing required key '" + std::string(key) + "' (" + spec(key).hint + ")");
  std::vector<double> values;
  for (size_t i = 0; i < line->values.size(); ++i)
    values.push_back(checkReal(*line, i, range, "value " + std::to_string(i + 1)));
  return values;
}

glm::dvec3 SectionReader::vec3(std::string_view key, glm::dvec3 fallback, Range range) {
  std::vector<double> v = reals(key, 3, std::vector<double>{fallback.x, fallback.y, fallback.z}, range);
  return {v[0], v[1], v[2]};
}

bool SectionReader::boolean(std::string_view key, bool fallback) {
  const ConfigLine* line = single(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  std::string v = toLower(line->values[0]);
  if (v == "true" || v == "1" || v == "yes" || v == "on") return true;
  if (v == "false" || v == "0" || v == "no" || v == "off") return false;
  throw InputError(line->where,
                   "'" + line->key + "': '" + line->values[0] + "' is not a boolean; use true or false");
}

std::string SectionReader::word(std::string_view key, const std::string& fallback,
                                const std::vector<std::string>& choices) {
  const ConfigLine* line = single(key);
  if (!line) return fallback;
  expectCount(*line, 1);
  for (const std::string& choice : choices)
    if (toLower(choice) == toLower(line->values[0])) return choice;
  std::string all;
  for (const std::string& choice : choices) all += (all.empty() ? "" : ", ") + choice;
  throw InputError(line->where, "'" + line->key + "': '" + line->values[0] + "' is not one of " + all);
}

PathRef SectionReader::path(std::string_view key) {
  const ConfigLine* line = single(key);
  if (!line) return {};
  expectCount(*line, 1);
  std::filesystem::path p(line->values[0]);
  bool fromCommandLine = line->where.line == 0;
  if (p.is_relative()) p = (fromCommandLine ? std::filesystem::path() : text_.baseDir) / p;
  return PathRef{p.lexically_normal(), line->where};
}

std::vector<const ConfigLine*> SectionReader::lines(std::string_view key) {
  spec(key);
  std::vector<const ConfigLine*> found;
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (canonicalKey(section_, text_.lines[i].key) != key) continue;
    used_[i] = true;
    found.push_back(&text_.lines[i]);
  }
  return found;
}

void SectionReader::finish() const {
  for (size_t i = 0; i < text_.lines.size(); ++i) {
    if (used_[i]) continue;
    const ConfigLine& line = text_.lines[i];
    if (canonicalKey(section_, line.key).empty())
      throw InputError(line.where, "unknown key '" + line.key + "' in " + section_.title +
                                       unknownKeyHint(section_, line.key));
    // A known key nobody read: the reader forgot it. Name it rather than ignore it.
    throw InputError(line.where, "key '" + line.key + "' is not used by this version of hairgen");
  }
}

}  // namespace hairgen
