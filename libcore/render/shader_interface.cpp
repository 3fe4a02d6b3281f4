#include "libcore/render/shader_interface.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <regex>
#include <sstream>

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

// `body` with its `in` declarations of the hair's shading inputs blanked out, for the atlas
// (StagePrelude::atlas): `[layout(...)] [qualifiers] in <type> vWorld;` and the like, one name each, the
// line breaks in them kept.
std::string atlasInputsAsGlobals(const std::string& body) {
  static const std::regex declaration(
      R"((layout\s*\([^)]*\)\s*)?((flat|smooth|noperspective|centroid|sample|highp|mediump|lowp)\s+)*)"
      R"(\bin\s+((highp|mediump|lowp)\s+)?\w+\s+(vWorld|vTangent|vColor|vNormal|vAlpha|vDepth)\s*;)");
  std::string out;
  auto last = body.cbegin();
  for (std::sregex_iterator m(body.begin(), body.end(), declaration), end; m != end; ++m) {
    out.append(last, (*m)[0].first);
    const std::string removed = m->str();
    out.append(size_t(std::count(removed.begin(), removed.end(), '\n')), '\n');
    last = (*m)[0].second;
  }
  return out.append(last, body.cend());
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
  if (prelude.atlas) return text + glsl::kAtlasInputs + "#line 1\n" + atlasInputsAsGlobals(body);
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
