#include "libcore/render/custom_shaders.h"

#include <algorithm>
#include <cctype>
#include <cstring>
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
constexpr size_t kMostStatementOperators = 1024;  // in one statement, its macros expanded
constexpr size_t kMostNesting = 64;               // parentheses, brackets and braces
constexpr size_t kMostInlinedTokens = 100000;     // a function's tokens with every call in it inlined

struct Token {
  std::string text;
  int line;
  size_t end;  // the offset just past it in the stage's text
};

// An operator's token (member access and the comma too): what makes an expression's tree deep, where
// names, numbers and brackets do not.
bool isOperator(const std::string& t) {
  return t.size() == 1 && std::strchr("+-*/%<>=!&|^~?:.,", t[0]) != nullptr;
}

bool isNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool isNamePart(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

// The stage's tokens (names and numbers whole, every other character one token, '.' too outside a
// number, so a chain of swizzles is as long as it is), without comments; the preprocessor's lines apart,
// each as its tokens.
void tokenise(std::string_view text, std::vector<Token>& code, std::vector<std::vector<Token>>& directives) {
  int line = 1;
  bool lineStart = true;
  std::vector<Token>* into = &code;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      // A line ends at LF, CR or CRLF (as the compiler's preprocessor reads them); a directive with it,
      // unless the line ends with a backslash.
      const bool continued = i > 0 && text[i - 1] == '\\';
      if (into != &code && !continued) into = &code;
      ++line;
      lineStart = true;
      i += c == '\r' && i + 1 < text.size() && text[i + 1] == '\n' ? 2 : 1;
      continue;
    }
    if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n' && text[i] != '\r') ++i;
      continue;
    }
    if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      i += 2;
      while (i + 1 < text.size() && !(text[i] == '*' && text[i + 1] == '/'))
        line += text[i++] == '\n';  // lines for messages only
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
    const bool digit = std::isdigit(static_cast<unsigned char>(c)) != 0;
    if (isNameStart(c)) {
      while (end < text.size() && isNamePart(text[end])) ++end;
    } else if (digit ||
               (c == '.' && end < text.size() && std::isdigit(static_cast<unsigned char>(text[end])))) {
      // A number: digits, a point, an exponent with its sign, a suffix.
      while (end < text.size() &&
             (isNamePart(text[end]) || text[end] == '.' ||
              ((text[end] == '+' || text[end] == '-') && (text[end - 1] == 'e' || text[end - 1] == 'E'))))
        ++end;
    }
    into->push_back({std::string(text.substr(i, end - i)), line, end});
    i = end;
  }
}

// A #define's cost where it is used, over every definition of its name (a name defined twice, under
// #if and #else or after an #undef, costs the most either could).
struct Macro {
  bool functionLike = false;  // or an object-like one whose body names a function-like macro
  std::vector<std::vector<Token>> bodies;
  std::vector<std::map<std::string, size_t>> parameters;  // per body: how often each appears in it
  size_t tokens = 0;            // its largest body's, macros in it expanded; parameters not counted
  size_t operators = 0;         // the operators among them
  size_t uses = 0;              // its parameters' appearances in that body
  size_t depth = 0;             // the deepest nesting its body opens, macros in it expanded
  std::set<std::string> names;  // every name it can expand to, macros in it expanded
  int state = 0;                // 0 unknown, 1 being costed, 2 costed
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
    for (const std::vector<Token>& d : directives) {
      // Token pasting makes names the bound cannot see (a call built as CAT(f, 0)): refused.
      for (size_t k = 0; k + 1 < d.size(); ++k)
        if (d[k].text == "#" && d[k + 1].text == "#" && d[k + 1].end == d[k].end + 1)
          fail(d[k].line,
               "## (token pasting) in a custom stage: it builds names hairgen's bound on the "
               "compiler's work cannot follow; write the names out");
      define(d);
    }
    for (auto& [name, m] : macros_) cost(name, m);
    statements(code);
    functions(code);
  }

 private:
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw InputError({stage_.file, line}, what);
  }

  // #define NAME BODY and #define NAME(PARAMETERS) BODY, every one the file holds (what #if, #else and
  // #undef keep of them is the compiler's to decide: each is costed).
  void define(const std::vector<Token>& d) {
    if (d.size() < 2 || d[0].text != "define") return;
    const Token& name = d[1];
    Macro& m = macros_[name.text];
    std::map<std::string, size_t> parameters;
    size_t k = 2;
    if (name.end < stage_.text.size() && stage_.text[name.end] == '(' && k < d.size() && d[k].text == "(") {
      m.functionLike = true;
      for (++k; k < d.size() && d[k].text != ")"; ++k)
        if (d[k].text != ",") parameters[d[k].text] = 0;
      ++k;
    }
    std::vector<Token> body;
    for (; k < d.size(); ++k) {
      if (const auto p = parameters.find(d[k].text); p != parameters.end()) {
        ++p->second;
        continue;
      }
      body.push_back(d[k]);
    }
    m.bodies.push_back(std::move(body));
    m.parameters.push_back(std::move(parameters));
    lines_[name.text] = name.line;
  }

  // A macro's cost from its bodies, the macros they name costed first (a cycle counts once, as the
  // preprocessor expands no macro within itself). A function-like macro whose body names another
  // (directly or through an object-like one) is refused: their nesting expands without bound.
  void cost(const std::string& name, Macro& m) {
    if (m.state == 2) return;
    if (m.state == 1) return;  // a cycle
    m.state = 1;
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      size_t tokens = 0, operators = 0, depth = 0, deepest = 0, uses = 0;
      for (const auto& [parameter, count] : m.parameters[b]) uses += count;
      for (const Token& t : m.bodies[b]) {
        m.names.insert(t.text);
        const auto inner = macros_.find(t.text);
        if (inner != macros_.end() && inner->first != name) {
          cost(inner->first, inner->second);
          if (inner->second.functionLike) {
            if (m.functionLike)
              fail(lines_[name], "#define " + name + "(...) uses the function-like macro " + t.text +
                                     "; in a custom stage a function-like macro's body uses none (their "
                                     "nesting expands without bound): write functions");
            m.functionLike = true;  // an alias of one: its uses are a function-like macro's
          }
          tokens = std::min(kMostInlinedTokens + 1, tokens + inner->second.tokens);
          operators = std::min(kMostStatementOperators + 1, operators + inner->second.operators);
          deepest = std::max(deepest, depth + inner->second.depth);
          m.names.insert(inner->second.names.begin(), inner->second.names.end());
          continue;
        }
        tokens = std::min(kMostInlinedTokens + 1, tokens + 1);
        operators += isOperator(t.text);
        if (t.text == "(" || t.text == "[" || t.text == "{") deepest = std::max(deepest, ++depth);
        if ((t.text == ")" || t.text == "]" || t.text == "}") && depth > 0) --depth;
      }
      m.tokens = std::max({m.tokens, tokens, size_t(1)});
      m.operators = std::max(m.operators, std::min(kMostStatementOperators + 1, operators));
      m.uses = std::max(m.uses, uses);
      m.depth = std::max(m.depth, deepest);
    }
    m.state = 2;
  }

  const Macro* macro(const std::string& token) const {
    const auto m = macros_.find(token);
    return m == macros_.end() ? nullptr : &m->second;
  }

  // An object-like macro's tokens, or 1 for any other token.
  size_t expanded(const std::string& token) const {
    const Macro* m = macro(token);
    return m == nullptr || m->functionLike ? 1 : m->tokens;
  }
  // An object-like macro's operators, or 1 for an operator, 0 for any other token.
  size_t operators(const std::string& token) const {
    const Macro* m = macro(token);
    return m == nullptr || m->functionLike ? size_t(isOperator(token)) : m->operators;
  }

  void tooLong(int line) const {
    fail(line, "a statement of more than " + std::to_string(kMostStatementOperators) +
                   " operators; a custom stage's statements have at most that many (a driver's compiler "
                   "takes time and memory that grow with the square of an expression's length): split it");
  }

  // No statement of more than kMostStatementOperators operators, its macros expanded (a function-like
  // macro's use: its body's, and each argument's as many times as its parameters appear there); nesting
  // at most kMostNesting, inside macros too.
  void statements(const std::vector<Token>& code) const {
    size_t tokens = 0, depth = 0;
    int start = 1;
    bool fresh = true;  // no token of this statement yet
    auto add = [&](size_t more) {
      tokens = std::min(kMostStatementOperators + 1, tokens + more);
      if (tokens > kMostStatementOperators) tooLong(start);
    };
    for (size_t k = 0; k < code.size(); ++k) {
      const Token& t = code[k];
      if (fresh) start = t.line;
      fresh = false;
      const Macro* m = macro(t.text);
      if (t.text == ";" || t.text == "{" || t.text == "}") {
        tokens = 0;
        fresh = true;
      } else if (m != nullptr && m->functionLike && k + 1 < code.size() && code[k + 1].text == "(") {
        k = macroUse(code, k, *m, depth, add);
        continue;
      } else {
        add(operators(t.text));
        if (m != nullptr) nestBy(t, depth, m->depth);
      }
      nest(t, depth);
    }
  }

  // A function-like macro's use at code[at] (its name; its arguments follow), `depth` the nesting it is
  // used at: what it expands to added, its arguments' nesting checked; returns the index of its closing
  // parenthesis.
  template <class Add>
  size_t macroUse(const std::vector<Token>& code, size_t at, const Macro& m, size_t depth, Add&& add) const {
    size_t level = 0, longest = 0, argument = 0, k = at + 1;
    nestBy(code[at], depth, m.depth);
    for (; k < code.size(); ++k) {
      const std::string& t = code[k].text;
      nest(code[k], depth);
      if (t == "(" && level++ == 0) continue;
      if (t == ")" && --level == 0) break;
      if (t == "," && level == 1) {
        longest = std::max(longest, argument);
        argument = 0;
        continue;
      }
      if (const Macro* inner = macro(t); inner != nullptr && inner->functionLike)
        fail(code[k].line, "the function-like macro " + t + " in the arguments of " + code[at].text +
                               "; a custom stage nests no function-like macros (their nesting expands "
                               "without bound): write functions");
      if (const Macro* inner = macro(t)) nestBy(code[k], depth, inner->depth);
      argument = std::min(kMostStatementOperators + 1, argument + operators(t));
    }
    longest = std::max(longest, argument);
    add(std::min(kMostStatementOperators + 1, m.operators + m.uses * longest));  // each use as the longest
    return k;
  }

  // Parentheses, brackets and braces at most kMostNesting deep.
  void nest(const Token& t, size_t& depth) const {
    if (t.text == "(" || t.text == "[" || t.text == "{") {
      nestBy(t, depth, 1);
      ++depth;
    } else if ((t.text == ")" || t.text == "]" || t.text == "}") && depth > 0) {
      --depth;
    }
  }
  void nestBy(const Token& t, size_t depth, size_t more) const {
    if (depth + more > kMostNesting)
      fail(t.line, "parentheses, brackets and braces nested more than " + std::to_string(kMostNesting) +
                       " deep; a custom stage nests at most that deep");
  }

  // Every function's tokens with the functions it calls inlined, as a compiler inlines them (every
  // overload of a name counted, and calls made through macros): at most kMostInlinedTokens.
  void functions(const std::vector<Token>& code) {
    struct Function {
      size_t tokens = 0;
      std::vector<std::string> calls;
      int line = 0;
    };
    std::map<std::string, Function> defined;
    size_t depth = 0;
    for (size_t k = 0; k < code.size(); ++k) {
      const std::string& t = code[k].text;
      if (depth == 0 && t == "(" && k > 0 && isNameStart(code[k - 1].text[0])) {
        // The parameter list, then a body or a ';' (a prototype).
        size_t close = k, level = 0;
        for (; close < code.size(); ++close) {
          if (code[close].text == "(") ++level;
          if (code[close].text == ")" && --level == 0) break;
        }
        if (close + 1 < code.size() && code[close + 1].text == "{") {
          Function& f = defined[code[k - 1].text];  // overloads add up
          if (f.line == 0) f.line = code[k - 1].line;
          size_t level2 = 0, b = close + 1;
          for (; b < code.size(); ++b) {
            if (code[b].text == "{") ++level2;
            if (code[b].text == "}" && --level2 == 0) break;
            f.tokens = std::min(kMostInlinedTokens + 1, f.tokens + expanded(code[b].text));
            if (b + 1 < code.size() && code[b + 1].text == "(" && isNameStart(code[b].text[0])) {
              f.calls.push_back(code[b].text);
              if (const Macro* m = macro(code[b].text))  // a call through a macro's name
                f.calls.insert(f.calls.end(), m->names.begin(), m->names.end());
            } else if (const Macro* m = macro(code[b].text)) {
              f.calls.insert(f.calls.end(), m->names.begin(), m->names.end());
            }
          }
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

  const CustomStage& stage_;
  std::map<std::string, Macro> macros_;
  std::map<std::string, int> lines_;  // where each macro was (last) defined
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
