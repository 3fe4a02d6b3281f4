// Config keys declared once (DESIGN §4). A section is a list of Key<S>, each naming its key, the
// thesis' other spellings, the value's shape, range and unit, a line of help, and how it reads into
// and writes out of the member of the section's struct S that it fills. The reader, the canonical text
// behind the config digest, `--set` and the key reference (`hairgen check --keys`) are all made from
// these declarations; the default a key documents is the one S's own initialiser gives.
//
// Builders for the usual shapes (realKey, integerKey, vectorKey, choiceKey, ...) cover most keys; a key
// with a layout of its own is a customKey with its own read and write.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "libcore/config/reader.h"
#include "libcore/util/text.h"

namespace hairgen {

template <class S>
struct Key {
  KeySpec spec;
  // Reads the key (it may be absent) into the struct. Throws InputError naming file and line.
  std::function<void(SectionReader&, S&)> read;
  // The canonical text of the value, one string per line (none for a repeatable key with no entry).
  std::function<std::vector<std::string>(const S&)> write;
};

template <class S>
struct Section {
  SectionSpec spec;  // the keys' specs, in declaration order, with their defaults filled in
  std::vector<Key<S>> keys;
  // Checks that involve several keys, after every key is read.
  std::function<void(SectionReader&, S&)> validate;
  // The section's canonical lines when its keys are not one line each (Collision's shapes keep one
  // order across three keys); otherwise every key's lines in declaration order.
  std::function<std::vector<std::string>(const S&)> canonical;

  // "Section.Key value" lines of every key that shapes the output.
  std::string canonicalText(const S& value) const;
};

// Builds a section: each key's documented default is what `write` makes of a default-constructed S.
template <class S>
Section<S> makeSection(std::string name, std::string title, std::string file, std::vector<Key<S>> keys,
                       std::function<void(SectionReader&, S&)> validate = {},
                       std::function<std::vector<std::string>(const S&)> canonical = {}) {
  Section<S> section;
  section.spec.name = std::move(name);
  section.spec.title = std::move(title);
  section.spec.file = std::move(file);
  const S defaults = S();  // not `S defaults{}`: GCC 12 then sees a maybe-uninitialised string
  for (Key<S>& key : keys) {
    if (!key.spec.required) {
      std::string text;
      for (const std::string& line : key.write(defaults)) text += (text.empty() ? "" : "; ") + line;
      key.spec.defaultText = text;
    }
    section.spec.keys.push_back(key.spec);
  }
  section.keys = std::move(keys);
  section.validate = std::move(validate);
  section.canonical = std::move(canonical);
  return section;
}

// Reads one file's text into S: every key in declaration order, then the section's checks, then a
// check that no line went unread.
template <class S>
S readSection(const Section<S>& section, const ConfigText& text, const std::vector<Override>& overrides) {
  SectionReader reader(text, section.spec, overrides);
  S value{};
  for (const Key<S>& key : section.keys) key.read(reader, value);
  if (section.validate) section.validate(reader, value);
  reader.finish();
  return value;
}

template <class S>
std::string Section<S>::canonicalText(const S& value) const {
  std::string out;
  if (canonical) {
    for (const std::string& line : canonical(value)) out += spec.name + "." + line + "\n";
    return out;
  }
  for (const Key<S>& key : keys) {
    if (!key.spec.inDigest) continue;
    for (const std::string& line : key.write(value))
      out += spec.name + "." + key.spec.name + " " + line + "\n";
  }
  return out;
}

// ------------------------------------------------------------------------------------------ builders

// What every builder takes besides the member: names, unit and help.
struct KeyText {
  std::string name;
  std::string unit;  // "" when dimensionless
  std::string help;
  std::vector<std::string> aliases = {};
};

namespace detail {
inline KeySpec spec(const KeyText& t, std::string value, std::string range) {
  KeySpec s;
  s.name = t.name;
  s.aliases = t.aliases;
  s.value = std::move(value);
  s.unit = t.unit;
  s.range = std::move(range);
  s.help = t.help;
  return s;
}
template <int N>
std::string join(const glm::vec<N, double>& v) {
  std::string out;
  for (int i = 0; i < N; ++i) out += (i ? " " : "") + formatReal(v[i]);
  return out;
}
}  // namespace detail

template <class S>
Key<S> realKey(KeyText t, double S::*member, Range range = {}) {
  std::string name = t.name;
  return {detail::spec(t, "real", range.describe()),
          [=](SectionReader& r, S& s) { s.*member = r.real(name, s.*member, range); },
          [=](const S& s) { return std::vector<std::string>{formatReal(s.*member)}; }};
}

template <class S>
Key<S> integerKey(KeyText t, int S::*member, int min, int max) {
  std::string name = t.name;
  return {detail::spec(t, "integer", "[" + std::to_string(min) + ", " + std::to_string(max) + "]"),
          [=](SectionReader& r, S& s) { s.*member = static_cast<int>(r.integer(name, s.*member, min, max)); },
          [=](const S& s) { return std::vector<std::string>{std::to_string(s.*member)}; }};
}

template <class S>
Key<S> unsignedKey(KeyText t, uint64_t S::*member) {
  std::string name = t.name;
  return {detail::spec(t, "integer", ">= 0"),
          [=](SectionReader& r, S& s) { s.*member = r.unsignedInteger(name, s.*member); },
          [=](const S& s) { return std::vector<std::string>{std::to_string(s.*member)}; }};
}

template <class S>
Key<S> boolKey(KeyText t, bool S::*member) {
  std::string name = t.name;
  return {detail::spec(t, "true | false", ""),
          [=](SectionReader& r, S& s) { s.*member = r.boolean(name, s.*member); },
          [=](const S& s) { return std::vector<std::string>{s.*member ? "true" : "false"}; }};
}

// N reals on one line into a glm vector: "x y z", "r g b", or N named components.
template <class S, int N>
Key<S> vectorKey(KeyText t, glm::vec<N, double> S::*member, std::string value, Range range = {}) {
  std::string name = t.name;
  return {detail::spec(t, std::move(value), range.describe()),
          [=](SectionReader& r, S& s) {
            std::vector<double> fallback(N);
            for (int i = 0; i < N; ++i) fallback[i] = (s.*member)[i];
            std::vector<double> v = r.reals(name, N, fallback, range);
            for (int i = 0; i < N; ++i) (s.*member)[i] = v[i];
          },
          [=](const S& s) { return std::vector<std::string>{detail::join<N>(s.*member)}; }};
}

// One word of a fixed list, into an enum; `name(E)` gives each value's spelling.
template <class S, class E>
Key<S> choiceKey(KeyText t, E S::*member, std::vector<E> values) {
  std::string name = t.name, shape;
  std::vector<std::string> words;
  for (E v : values) {
    words.push_back(hairgen::name(v));
    shape += (shape.empty() ? "" : " | ") + words.back();
  }
  return {detail::spec(t, shape, ""),
          [=](SectionReader& r, S& s) {
            std::string word = r.word(name, hairgen::name(s.*member), words);
            for (E v : values)
              if (word == hairgen::name(v)) s.*member = v;
          },
          [=](const S& s) { return std::vector<std::string>{hairgen::name(s.*member)}; }};
}

// A path, resolved against the naming file's folder. Paths never enter the digest.
template <class S>
Key<S> pathKey(KeyText t, PathRef S::*member) {
  std::string name = t.name;
  Key<S> key{detail::spec(t, "path", ""), [=](SectionReader& r, S& s) { s.*member = r.path(name); },
             [=](const S& s) {
               return (s.*member).given() ? std::vector<std::string>{(s.*member).path.string()}
                                          : std::vector<std::string>{};
             }};
  key.spec.inDigest = false;
  return key;
}

// A key with a layout of its own.
template <class S>
Key<S> customKey(KeyText t, std::string value, std::string range,
                 std::function<void(SectionReader&, S&)> read,
                 std::function<std::vector<std::string>(const S&)> write) {
  return {detail::spec(t, std::move(value), std::move(range)), std::move(read), std::move(write)};
}

// Marks a key that only some values of the section's Model read (Dynamics Info's anjyo or springs): its
// help is prefixed with them ("anjyo: ...") and the section's check refuses it under any other Model.
template <class S>
Key<S> onlyFor(std::vector<std::string> models, Key<S> key) {
  std::string prefix;
  for (const std::string& model : models) prefix += (prefix.empty() ? "" : ", ") + model;
  key.spec.help = prefix + ": " + key.spec.help;
  key.spec.models = std::move(models);
  return key;
}

// Marks a key: required (no default), or repeatable (any number of lines, in file order).
template <class S>
Key<S> required(Key<S> key) {
  key.spec.required = true;
  return key;
}
template <class S>
Key<S> repeatable(Key<S> key) {
  key.spec.repeatable = true;
  return key;
}

}  // namespace hairgen
