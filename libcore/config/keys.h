// The declarations of every config key, section by section (keys.cpp), and the readers made from them.
#pragma once

#include <vector>

#include "libcore/config/params.h"
#include "libcore/config/reader.h"
#include "libcore/config/schema.h"

namespace hairgen {

const Section<Setup>& setupKeys();
const Section<Hairstyle>& hairstyleKeys();
const Section<Collision>& collisionKeys();
const Section<Visuality>& visualityKeys();
const Section<RenderSettings>& renderKeys();
const Section<Dynamics>& dynamicsKeys();

// Each reader parses one file's text (after applying the overrides of its section) and rejects any
// unknown, duplicate, malformed, non-finite or out-of-range value with its file:line.
Setup readSetup(const ConfigText& text, const std::vector<Override>& overrides);
Hairstyle readHairstyle(const ConfigText& text, const std::vector<Override>& overrides);
Collision readCollision(const ConfigText& text, const std::vector<Override>& overrides);
Visuality readVisuality(const ConfigText& text, const std::vector<Override>& overrides);
RenderSettings readRender(const ConfigText& text, const std::vector<Override>& overrides);
Dynamics readDynamics(const ConfigText& text, const std::vector<Override>& overrides);

}  // namespace hairgen
