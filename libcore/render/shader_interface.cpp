#include "libcore/render/shader_interface.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <iterator>
#include <regex>
#include <sstream>
#include <vector>

#include "glsl/embedded_glsl.h"
#include "libcore/config/params.h"
#include "libcore/render/camera_fragments.h"
#include "libcore/render/hair_raster.h"

namespace hairgen {

static_assert(kUnitAtlasData + 1 == kTextureUnitCount, "kTextureUnitCount counts every TextureUnit");

const char* name(TextureUnit unit) {
  switch (unit) {
    case kUnitHairStart:
      return "kUnitHairStart";
    case kUnitHeadDepth:
      return "kUnitHeadDepth";
    case kUnitOpacityMap:
      return "kUnitOpacityMap";
    case kUnitSubpixelColor:
      return "kUnitSubpixelColor";
    case kUnitSubpixelData:
      return "kUnitSubpixelData";
    case kUnitSubpixelMotion:
      return "kUnitSubpixelMotion";
    case kUnitAtlasColor:
      return "kUnitAtlasColor";
    case kUnitAtlasData:
      break;
  }
  return "kUnitAtlasData";
}

namespace {

// "kajiya-kay" → "KajiyaKay"
std::string camelCase(const std::string& words) {
  std::string out;
  bool capital = true;
  for (char c : words) {
    if (c == '-' || c == '_' || c == ' ') {
      capital = true;
      continue;
    }
    out += capital ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    capital = false;
  }
  return out;
}

// The shortest decimal that reads back as `value`, so GLSL gets the very float C++ has.
std::string glslFloat(float value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  std::string s(text, end);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

// The hair shading stage's inputs, as hair_vertex.glsl writes them, and their fields in HairgenInputs
// (glsl/atlas_inputs.glsl).
struct HairInput {
  const char* name;
  const char* field;
};
constexpr HairInput kHairInputs[] = {{"vWorld", "world"},   {"vTangent", "tangent"}, {"vColor", "color"},
                                     {"vNormal", "normal"}, {"vAlpha", "alpha"},     {"vDepth", "depth"}};

// `text` with each comment turned to spaces (its line breaks kept): the same length, so what is found
// in it is at the same place in `text`.
std::string withoutComments(const std::string& text) {
  std::string out = text;
  for (size_t i = 0; i + 1 < out.size(); ++i) {
    if (out[i] != '/' || (out[i + 1] != '/' && out[i + 1] != '*')) continue;
    const bool line = out[i + 1] == '/';
    size_t end = line ? out.find('\n', i) : out.find("*/", i + 2);
    end = end == std::string::npos ? out.size() : (line ? end : end + 2);
    for (size_t k = i; k < end; ++k)
      if (out[k] != '\n') out[k] = ' ';
    i = end - 1;
  }
  return out;
}

// The hair's shading stage as it runs on the atlas (StagePrelude::atlas), after glsl/atlas_inputs.glsl:
//   - each `in` declaration all of whose names are hair inputs (`in vec3 vWorld;`, `flat in vec3 vColor;`,
//     `layout(location = 1) in float vAlpha, vDepth;`) becomes a plain global: its qualifiers (in,
//     layout, interpolation, precision) are overwritten with spaces, so lines and columns stay the file's;
//   - after it, hairgen's main(): the fragment's inputs into those globals, then the stage's own main()
//     (renamed hairgenShade by the prelude). It reads gl_FragCoord after the stage, which may redeclare it
//     (origin_upper_left counts rows from the top).
// A stage with no main() is left without hairgen's, so the linker says so as it would anywhere.
std::string forTheAtlas(const std::string& body) {
  static const std::regex declaration(
      R"(((?:(?:layout\s*\([^)]*\)|\b(?:in|flat|smooth|noperspective|centroid|sample|highp|mediump|lowp)\b)\s*)+))"
      R"((\w+)\s+([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*)\s*;)");
  static const std::regex inWord(R"(\bin\b)"), name(R"([A-Za-z_]\w*)"), mainFunction(R"(\bmain\s*\()");
  const std::string code = withoutComments(body);
  std::string out = body;
  bool declared[std::size(kHairInputs)] = {};
  for (std::sregex_iterator m(code.begin(), code.end(), declaration), end; m != end; ++m) {
    if (!std::regex_search(m->str(1), inWord)) continue;
    const std::string names = m->str(3);
    std::vector<size_t> inputs;
    for (std::sregex_iterator n(names.begin(), names.end(), name); n != end; ++n) {
      const auto* found = std::find_if(std::begin(kHairInputs), std::end(kHairInputs),
                                       [&](const HairInput& input) { return n->str() == input.name; });
      if (found == std::end(kHairInputs)) break;
      inputs.push_back(size_t(found - std::begin(kHairInputs)));
    }
    if (inputs.size() != size_t(std::count(names.begin(), names.end(), ',')) + 1) continue;
    for (size_t k = size_t(m->position(1)); k < size_t(m->position(1) + m->length(1)); ++k)
      if (out[k] != '\n') out[k] = ' ';
    for (size_t input : inputs) declared[input] = true;
  }
  if (!std::regex_search(code, mainFunction)) return out;
  const bool fromTop = code.find("origin_upper_left") != std::string::npos;
  out +=
      "\n#undef main\nvoid main() {\n  HairgenInputs hairgenIn;\n  ivec2 hairgenTexel = "
      "ivec2(gl_FragCoord.xy);\n";
  if (fromTop) out += "  hairgenTexel.y = hairgenAtlasRows - 1 - hairgenTexel.y;\n";
  out += "  if (!hairgenInputs(hairgenTexel, hairgenIn)) discard;\n";
  for (size_t k = 0; k < std::size(kHairInputs); ++k)
    if (declared[k])
      out += std::string("  ") + kHairInputs[k].name + " = hairgenIn." + kHairInputs[k].field + ";\n";
  return out + "  hairgenShade();\n}\n";
}

}  // namespace

std::string glslConstants() {
  std::string out;
  for (ShadingModel model : kShadingModels)
    out += "const int kShading" + camelCase(name(model)) + " = " + std::to_string(static_cast<int>(model)) +
           ";\n";
  for (int unit = 0; unit < kTextureUnitCount; ++unit)
    out += std::string("const int ") + name(TextureUnit(unit)) + " = " + std::to_string(unit) + ";\n";
  out += "const float kShadowBiasHair = " + glslFloat(kShadowBiasHair) + ";\n";
  out += "const float kShadowFloor = " + glslFloat(kShadowFloor) + ";\n";
  out += "const float kShadowOffsetHead = " + glslFloat(kShadowOffsetHead) + ";\n";
  out += "const float kShadowBiasHeadDepth = " + glslFloat(kShadowBiasHeadDepth) + ";\n";
  out += "const float kBackgroundZ = " + glslFloat(kBackgroundZ) + ";\n";
  out += "const uint kCoverageOne = " + std::to_string(kCoverageOne) + "u;\n";
  out += "const int kCoverageBits = " + std::to_string(kCoverageBits) + ";\n";
  out += "const uint kSpanUnit = " + std::to_string(kSpanUnit) + "u;\n";
  return out;
}

std::string assembleStage(const StagePrelude& prelude, const std::string& body) {
  std::string text = "#version 450 core\n";
  if (prelude.ribbon) text += "#define RIBBON\n";
  if (prelude.motion) text += "#define MOTION\n";
  if (prelude.singleSample) text += "#define SINGLE_SAMPLE\n";
  text += prelude.defines;
  text += glslConstants();
  if (prelude.shadowFunction) text += glsl::kShadow;
  if (prelude.screenDoor) text += std::string("#define SCREEN_DOOR\n") + glsl::kScreenDoor;
  if (prelude.atlas) return text + glsl::kAtlasInputs + "#line 1\n" + forTheAtlas(body);
  return text + "#line 1\n" + body;
}

CompilerMessage firstCompilerError(const std::string& log) {
  std::istringstream lines(log);
  std::string line, first, firstError;
  while (std::getline(lines, line)) {
    line.erase(0, line.find_first_not_of(" \t\r"));
    line.erase(line.find_last_not_of(" \t\r") + 1);
    if (line.empty()) continue;
    if (first.empty()) first = line;
    std::string lower = line;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (lower.find("error") != std::string::npos) {
      firstError = line;
      break;
    }
  }
  const std::string& chosen = firstError.empty() ? first : firstError;
  // string:line(column): / string(line) : / ERROR: string:line:
  static const std::regex mesa(R"(^\d+:(\d+)\(\d+\):\s*(.*)$)"), nvidia(R"(^\d+\((\d+)\)\s*:\s*(.*)$)"),
      glslang(R"(^ERROR:\s*\d+:(\d+):\s*(.*)$)", std::regex::icase),
      errorWord(R"(^error:\s*)", std::regex::icase);
  CompilerMessage out{0, chosen};
  std::smatch m;
  if (std::regex_match(chosen, m, mesa) || std::regex_match(chosen, m, nvidia) ||
      std::regex_match(chosen, m, glslang))
    out = {std::stoi(m[1].str()), m[2].str()};
  out.text = std::regex_replace(out.text, errorWord, "");
  if (out.text.empty()) out.text = "the GLSL compiler gave no reason";
  return out;
}

}  // namespace hairgen
