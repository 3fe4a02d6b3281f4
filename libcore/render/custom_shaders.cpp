#include "libcore/render/custom_shaders.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>
#include <string_view>
#include <vector>

#include "libcore/util/error.h"
#include "libcore/util/file_util.h"

namespace hairgen {

namespace {

// What a driver's GLSL compiler is given of a custom stage, bounded before it sees it: llvmpipe's took
// 6 GB and 20 s for one statement of 5,000 additions, and crashed at 20,000 (its cost grows with the
// square of an expression's length), and a compiler inlines every function, so a few lines of functions
// that each call the one before twice ask for 2^30 copies. A real stage is a few thousand tokens; its
// longest statement a few hundred.
constexpr size_t kMostBytes = 256 * 1024;
constexpr size_t kMostStatementTokens = 1024;  // in one statement, its macros expanded
constexpr size_t kMostNesting = 64;            // parentheses, brackets and braces
constexpr size_t kMostInlinedTokens = 100000;  // a function's tokens with every call in it inlined

struct Token {
  std::string text;
  int line;
  size_t end;  // the offset just past it in the stage's text
};

// The stage's tokens (identifiers and numbers whole, every other character one token), without
// comments; the preprocessor's lines apart, each as its tokens.
void tokenise(std::string_view text, std::vector<Token>& code, std::vector<std::vector<Token>>& directives) {
  int line = 1;
  bool lineStart = true;
  std::vector<Token>* into = &code;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\n') {
      // A directive ends at its line's end, unless the line ends with a backslash.
      if (into != &code && !(i > 0 && text[i - 1] == '\\')) into = &code;
      ++line;
      lineStart = true;
      ++i;
      continue;
    }
    if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n') ++i;
      continue;
    }
    if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      i += 2;
      while (i + 1 < text.size() && !(text[i] == '*' && text[i + 1] == '/')) line += text[i++] == '\n';
      i += 2;
      continue;
    }
    if (std::isspace(static_cast<unsigned char>(c)) || c == '\\') {
      ++i;
      continue;
    }
    if (c == '#' && lineStart) {
      directives.emplace_back();
      into = &directives.back();
      lineStart = false;
      ++i;
      continue;
    }
    lineStart = false;
    size_t end = i + 1;
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.')
      while (end < text.size() &&
             (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '_' || text[end] == '.'))
        ++end;
    into->push_back({std::string(text.substr(i, end - i)), line, end});
    i = end;
  }
}

// A #define's cost where it is used.
struct Macro {
  size_t tokens = 0;  // its body's, object-like macros in it expanded; parameters not counted
  bool functionLike = false;
  std::map<std::string, size_t> parameters;  // how often each appears in the body
};

class Bounds {
 public:
  explicit Bounds(const CustomStage& stage) : stage_(stage) {}

  void check() {
    if (stage_.text.size() > kMostBytes)
      fail(0, std::to_string(stage_.text.size()) + " bytes; a custom stage is at most " +
                  std::to_string(kMostBytes));
    std::vector<Token> code;
    std::vector<std::vector<Token>> directives;
    tokenise(stage_.text, code, directives);
    for (const std::vector<Token>& d : directives) directive(d);
    statements(code);
    functions(code);
  }

 private:
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw InputError({stage_.file, line}, what);
  }

  // #define NAME BODY and #define NAME(PARAMETERS) BODY: a macro's tokens, those of the macros in its
  // body expanded, and for a function-like one how often each parameter appears in its body. A
  // function-like macro's body may not use another function-like one (their nesting expands without
  // bound).
  void directive(const std::vector<Token>& d) {
    if (d.size() < 2 || d[0].text != "define") return;
    const Token& name = d[1];
    Macro m;
    size_t k = 2;
    if (name.end < stage_.text.size() && stage_.text[name.end] == '(' && k < d.size() && d[k].text == "(") {
      m.functionLike = true;
      for (++k; k < d.size() && d[k].text != ")"; ++k)
        if (d[k].text != ",") m.parameters[d[k].text] = 0;
      ++k;
    }
    for (; k < d.size(); ++k) {
      if (const auto p = m.parameters.find(d[k].text); m.functionLike && p != m.parameters.end()) {
        ++p->second;
        continue;
      }
      const auto other = macros_.find(d[k].text);
      if (m.functionLike && other != macros_.end() && other->second.functionLike)
        fail(name.line, "#define " + name.text + "(...) uses the function-like macro " + d[k].text +
                            "; in a custom stage a function-like macro's body uses none (their nesting "
                            "expands without bound): write functions");
      m.tokens = std::min(kMostStatementTokens + 1, m.tokens + expanded(d[k].text));
    }
    m.tokens = std::max<size_t>(m.tokens, 1);
    macros_[name.text] = m;
  }

  // An object-like macro's tokens, or 1 for any other token.
  size_t expanded(const std::string& token) const {
    const auto m = macros_.find(token);
    return m == macros_.end() || m->second.functionLike ? 1 : m->second.tokens;
  }

  // No statement longer than kMostStatementTokens, its macros expanded (a function-like macro's use: its
  // body, and each argument as many times as its parameter appears there); nesting at most kMostNesting.
  void statements(const std::vector<Token>& code) const {
    size_t tokens = 0, depth = 0;
    int start = 1;
    auto add = [&](size_t more) {
      tokens = std::min(kMostStatementTokens + 1, tokens + more);
      if (tokens > kMostStatementTokens)
        fail(start, "a statement of more than " + std::to_string(kMostStatementTokens) +
                        " tokens; a custom stage's statements are at most that long (a driver's "
                        "compiler takes time and memory that grow with the square of an "
                        "expression's length): split it");
    };
    for (size_t k = 0; k < code.size(); ++k) {
      const Token& t = code[k];
      if (tokens == 0) start = t.line;
      if (t.text == ";" || t.text == "{" || t.text == "}") {
        tokens = 0;
      } else if (const auto m = macros_.find(t.text); m != macros_.end() && m->second.functionLike &&
                                                      k + 1 < code.size() && code[k + 1].text == "(") {
        k = macroUse(code, k, m->second, add);
        continue;
      } else {
        add(expanded(t.text));
      }
      nest(t, depth);
    }
  }

  // A function-like macro's use at code[at] (its name; its arguments follow): what it expands to added,
  // its arguments' nesting checked; returns the index of its closing parenthesis.
  template <class Add>
  size_t macroUse(const std::vector<Token>& code, size_t at, const Macro& m, Add&& add) const {
    size_t level = 0, arguments = 0, argument = 0, k = at + 1, depth = 0;
    for (; k < code.size(); ++k) {
      const std::string& t = code[k].text;
      nest(code[k], depth);
      if (t == "(" && level++ == 0) continue;
      if (t == ")" && --level == 0) break;
      if (t == "," && level == 1) {
        arguments = std::max(arguments, argument);
        argument = 0;
        continue;
      }
      if (const auto inner = macros_.find(t); inner != macros_.end() && inner->second.functionLike)
        fail(code[k].line, "the function-like macro " + t + " in the arguments of " + code[at].text +
                               "; a custom stage nests no function-like macros (their nesting expands "
                               "without bound): write functions");
      argument += expanded(t);
    }
    arguments = std::max(arguments, argument);
    size_t uses = 0;
    for (const auto& [parameter, count] : m.parameters) uses += count;
    add(m.tokens + uses * arguments);  // each parameter's use as long as the longest argument
    return k;
  }

  // Parentheses, brackets and braces at most kMostNesting deep.
  void nest(const Token& t, size_t& depth) const {
    if (t.text == "(" || t.text == "[" || t.text == "{") {
      if (++depth > kMostNesting)
        fail(t.line, "parentheses, brackets and braces nested more than " + std::to_string(kMostNesting) +
                         " deep; a custom stage nests at most that deep");
    } else if ((t.text == ")" || t.text == "]" || t.text == "}") && depth > 0) {
      --depth;
    }
  }

  // Every function's tokens with the functions it calls inlined, as a compiler inlines them: at most
  // kMostInlinedTokens.
  void functions(const std::vector<Token>& code) {
    // Top-level definitions: NAME ( ... ) { BODY }.
    struct Function {
      size_t tokens = 0;
      std::vector<std::string> calls;
      int line = 0;
    };
    std::map<std::string, Function> defined;
    size_t depth = 0;
    for (size_t k = 0; k < code.size(); ++k) {
      const std::string& t = code[k].text;
      if (depth == 0 && t == "(" && k > 0 && isName(code[k - 1].text)) {
        // The parameter list, then a body or a ';' (a prototype).
        size_t close = k, level = 0;
        for (; close < code.size(); ++close) {
          if (code[close].text == "(") ++level;
          if (code[close].text == ")" && --level == 0) break;
        }
        if (close + 1 < code.size() && code[close + 1].text == "{") {
          Function f;
          f.line = code[k - 1].line;
          size_t level2 = 0, b = close + 1;
          for (; b < code.size(); ++b) {
            if (code[b].text == "{") ++level2;
            if (code[b].text == "}" && --level2 == 0) break;
            f.tokens += expanded(code[b].text);
            if (code[b].text == "(" && b > 0 && isName(code[b - 1].text)) f.calls.push_back(code[b - 1].text);
          }
          defined[code[k - 1].text] = std::move(f);
          k = b;
          continue;
        }
      }
      if (t == "{") ++depth;
      if (t == "}" && depth > 0) --depth;
    }
    std::map<std::string, size_t> inlined;
    std::set<std::string> visiting;
    // Recursion is illegal in GLSL; a cycle here counts once (the compiler refuses it anyway).
    auto size = [&](auto&& self, const std::string& name) -> size_t {
      if (const auto known = inlined.find(name); known != inlined.end()) return known->second;
      const auto f = defined.find(name);
      if (f == defined.end() || !visiting.insert(name).second) return 0;
      size_t total = f->second.tokens;
      for (const std::string& callee : f->second.calls)
        total = std::min(kMostInlinedTokens + 1, total + self(self, callee));
      visiting.erase(name);
      return inlined[name] = total;
    };
    for (const auto& [name, f] : defined)
      if (const size_t total = size(size, name); total > kMostInlinedTokens)
        fail(f.line, name + "() with the functions it calls inlined is more than " +
                         std::to_string(kMostInlinedTokens) +
                         " tokens (a compiler inlines every call); a custom stage's functions are at most "
                         "that large");
  }

  static bool isName(const std::string& t) {
    return !t.empty() && (std::isalpha(static_cast<unsigned char>(t[0])) || t[0] == '_');
  }

  const CustomStage& stage_;
  std::map<std::string, Macro> macros_;
};

}  // namespace

void requireBoundedStage(const CustomStage& stage) {
  Bounds(stage).check();
}

CustomShaders readCustomShaders(const Setup& setup) {
  auto read = [](const PathRef& ref) -> std::optional<CustomStage> {
    if (!ref.given()) return std::nullopt;
    CustomStage stage{readFileText(ref.path), ref.path.string(), ref.where.str()};
    requireBoundedStage(stage);
    return stage;
  };
  return {read(setup.hairVert), read(setup.hairFrag), read(setup.headVert), read(setup.headFrag)};
}

}  // namespace hairgen
