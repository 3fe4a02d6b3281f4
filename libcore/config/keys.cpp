// Every config key hairgen reads, declared once (DESIGN §4), a file per section: keys_setup.cpp,
// keys_hairstyle.cpp, keys_collision.cpp, keys_visuality.cpp, keys_render.cpp and keys_dynamics.cpp,
// with the helpers they share in key_helpers.h. The reader, the canonical text behind the config digest,
// --set and `hairgen check --keys` all come from these tables; a new key is one declaration in its
// section's file and the code that uses its value. Here: the sections, made once, and their readers.
#include "libcore/config/keys.h"

#include "libcore/config/key_helpers.h"

namespace hairgen {

const Section<Setup>& setupKeys() {
  static const Section<Setup> section = keydecl::makeSetup();
  return section;
}
const Section<Hairstyle>& hairstyleKeys() {
  static const Section<Hairstyle> section = keydecl::makeHairstyle();
  return section;
}
const Section<Collision>& collisionKeys() {
  static const Section<Collision> section = keydecl::makeCollision();
  return section;
}
const Section<Visuality>& visualityKeys() {
  static const Section<Visuality> section = keydecl::makeVisuality();
  return section;
}
const Section<RenderSettings>& renderKeys() {
  static const Section<RenderSettings> section = keydecl::makeRender();
  return section;
}

const Section<Dynamics>& dynamicsKeys() {
  static const Section<Dynamics> section = keydecl::makeDynamics();
  return section;
}

const SectionList& allSections() {
  static const SectionList sections = {&setupKeys().spec,     &hairstyleKeys().spec, &collisionKeys().spec,
                                       &visualityKeys().spec, &renderKeys().spec,    &dynamicsKeys().spec};
  return sections;
}

Setup readSetup(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(setupKeys(), text, overrides);
}
Hairstyle readHairstyle(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(hairstyleKeys(), text, overrides);
}
Collision readCollision(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(collisionKeys(), text, overrides);
}
Visuality readVisuality(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(visualityKeys(), text, overrides);
}
RenderSettings readRender(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(renderKeys(), text, overrides);
}
Dynamics readDynamics(const ConfigText& text, const std::vector<Override>& overrides) {
  return readSection(dynamicsKeys(), text, overrides);
}

std::string Config::canonicalText() const {
  // Dynamics only when the Setup names a Dynamics Info, so that a still coupe's digest is the one it
  // had before hairgen could simulate.
  // Then the inputs whose bytes shape the output, by content (inputContent): a line each.
  std::string inputs;
  for (const auto& [key, content] : inputContent) inputs += "Input." + key + " " + content + "\n";
  return setupKeys().canonicalText(setup) + hairstyleKeys().canonicalText(hairstyle) +
         collisionKeys().canonicalText(collision) + visualityKeys().canonicalText(visuality) +
         renderKeys().canonicalText(render) + (dynamics.given ? dynamicsKeys().canonicalText(dynamics) : "") +
         inputs;
}

}  // namespace hairgen
