// Shell text: the only place plan data becomes shell. Every byte of plan data that reaches a shell
// passes through shellQuote, and every shell variable through shellWord; nothing else writes shell.
#pragma once

#include <string>
#include <vector>

namespace hairgen::farm {

// A piece of one shell word: literal text, or a shell variable's value ("${name}", or
// "${name:-fallback}" where fallback is a count).
struct ShellPiece {
  std::string text;  // the literal text, or the variable's name
  bool variable = false;
  std::string fallback;
};
using ShellWord = std::vector<ShellPiece>;

ShellPiece textPiece(std::string text);
ShellWord literal(std::string text);

// `s` single-quoted: the shell reads every byte as itself. A control character (which a valid plan
// never holds) is refused (InputError) rather than quoted, so no line of a script is ever split.
std::string shellQuote(const std::string& s);

// One word: literal pieces single-quoted, variables double-quoted, side by side.
std::string shellWord(const ShellWord& word);

// Words joined by spaces.
std::string shellLine(const std::vector<ShellWord>& words);

// The word as a program's argument, every piece literal (a real submission knows its job ids).
std::string argument(const ShellWord& word);

}  // namespace hairgen::farm
