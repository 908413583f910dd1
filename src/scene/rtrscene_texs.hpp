#pragma once
// The TEXS chunk of .rtrscene version 6 (docs/rtrscene-format.md): the body's writer and reader, for
// rtrscene.cpp, which frames the chunks.
#include <memory>
#include <span>
#include <string>

#include "scene/binio.hpp"
#include "scene/scene.hpp"

namespace rtr {

// Whether the scene has baked texels: all of its textures, or none (a mix is refused by writeTexs).
bool hasBakedTextures(const Scene& scene);
void writeTexs(ByteWriter& w, const Scene& scene);
// Reads the body that ends at `end` into scene.textures[i].baked; `owner` keeps `bytes` alive (null: the
// stored pieces are copied). Faults throw rtr::Error naming the file and byte offset.
void readTexs(ByteReader& r, size_t end, std::span<const uint8_t> bytes, Scene& scene, const std::shared_ptr<const void>& owner,
              const std::string& file);

}  // namespace rtr
