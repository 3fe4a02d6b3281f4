#include "farm/shell.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "libcore/util/error.h"
#include "libcore/util/text.h"

namespace hairgen::farm {
namespace {

bool isShellName(const std::string& s) {
  return !s.empty() && !std::isdigit(static_cast<unsigned char>(s[0])) &&
         std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

}  // namespace

ShellPiece textPiece(std::string text) {
  return ShellPiece{std::move(text), false, {}};
}
ShellWord literal(std::string text) {
  return {textPiece(std::move(text))};
}

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (isControl(c))
      throw InputError("a control character in '" + oneLine(s) + "' cannot go into a shell script");
    out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return out + "'";
}

std::string shellWord(const ShellWord& word) {
  std::string out;
  for (const ShellPiece& p : word) {
    if (!p.variable) {
      out += shellQuote(p.text);
      continue;
    }
    if (!isShellName(p.text) || p.fallback.find_first_not_of("0123456789") != std::string::npos)
      throw std::logic_error("not a shell variable: " + p.text + " " + p.fallback);
    out += "\"${" + p.text + (p.fallback.empty() ? "" : ":-" + p.fallback) + "}\"";
  }
  return out.empty() ? "''" : out;
}

std::string shellLine(const std::vector<ShellWord>& words) {
  std::string line;
  for (const ShellWord& w : words) line += (line.empty() ? "" : " ") + shellWord(w);
  return line;
}

std::string argument(const ShellWord& word) {
  std::string out;
  for (const ShellPiece& p : word) {
    if (p.variable) throw std::logic_error("an unset shell variable in an argument: " + p.text);
    out += p.text;
  }
  return out;
}

}  // namespace hairgen::farm
