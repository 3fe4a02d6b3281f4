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

}  // namespace hairgen
