// Locale-free text helpers: number parsing with std::from_chars, case folding, edit distance.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace hairgen {

// Parses the whole of `text` as a real number ("+0.068", "1e-4"). Accepts a leading '+', rejects
// trailing characters. Returns nullopt when malformed; the value may be non-finite ("nan", "inf").
std::optional<double> parseReal(std::string_view text);

// Parses the whole of `text` as a base-10 integer (leading '+' allowed).
std::optional<int64_t> parseInt(std::string_view text);
std::optional<uint64_t> parseUInt(std::string_view text);

std::string toLower(std::string_view text);

// Levenshtein distance, case-insensitive.
int editDistance(std::string_view a, std::string_view b);

// The candidate closest to `word` if it is close enough to be a plausible typo, else "".
std::string closestMatch(std::string_view word, const std::vector<std::string>& candidates);

// Shortest text that parses back to the same double (std::to_chars).
std::string formatReal(double value);
std::string formatFloat(float value);  // shortest text that parses back to the same float
// `value` to `digits` significant digits (printf's %g), for a message: 0.000123, 4.56e+07.
std::string formatSignificant(double value, int digits = 3);
// A 64-bit digest as 16 lowercase hex digits, leading zeros kept: "00ff00ff00ff00ff".
std::string formatDigest(uint64_t digest);

// `text` with every line end replaced by a space: library messages (a compiler's log, a parser's
// warnings) in hairgen's one-line errors.
std::string oneLine(std::string text);

// `text` as it may appear in any text hairgen writes (a .usda string, glTF's JSON, a PLY header's
// comment, `info`'s lines and JSON), the one escaping every text writer applies to text that came from
// a file: valid UTF-8 is kept; a byte that does not begin a valid UTF-8 sequence (an overlong form, a
// surrogate, past U+10FFFF, cut short) becomes U+FFFD; a control character (U+0000-U+001F and U+007F,
// line ends and tabs included) becomes the four characters \xNN and one of U+0080-U+009F the six
// characters \u00NN, so NUL, line ends and terminal controls never reach a format's syntax.
std::string printableText(std::string_view text);

// Whether `c` is one of the ASCII control characters printableText escapes (U+0000-U+001F, U+007F).
inline bool isControl(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u < 0x20 || u == 0x7f;
}

// `text` without a leading UTF-8 byte-order mark (editors on Windows write one).
std::string_view withoutBom(std::string_view text);

// Calls visit(line, number) for each line of `text` (numbers from 1, without the line end). A line
// ends at "\r\n", "\n" or a lone "\r" (old Mac editors), as tinyobjloader reads them, so a validator
// and the parser behind it see the same lines. A final line end starts no extra line.
template <class Visit>
void forEachLine(std::string_view text, Visit&& visit) {
  size_t pos = 0;
  int number = 0;
  while (pos < text.size()) {
    size_t end = text.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    visit(text.substr(pos, end - pos), ++number);
    pos = end + (end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n' ? 2 : 1);
  }
}

}  // namespace hairgen
