#pragma once
// Every field of two scenes compared (gtest expectations), for round trips through the baked formats.
// `texturePaths` false skips the texture paths (a bake renames them) and `Texture::bytes`.
#include <gtest/gtest.h>

#include "scene/scene.hpp"

namespace rtr::test {

inline void expectSameUv(const UvTransform& a, const UvTransform& b) {
  EXPECT_EQ(a.offset, b.offset);
  EXPECT_EQ(a.rotation, b.rotation);
  EXPECT_EQ(a.scale, b.scale);
  EXPECT_EQ(a.texCoord, b.texCoord);
}

inline void expectSameMaterial(const Material& a, const Material& b) {
  SCOPED_TRACE("material " + a.name);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.flags, b.flags);
  EXPECT_EQ(a.baseColor, b.baseColor);
  EXPECT_EQ(a.roughness, b.roughness);
  EXPECT_EQ(a.metalness, b.metalness);
  EXPECT_EQ(a.emissive, b.emissive);
  EXPECT_EQ(a.opacity, b.opacity);
  EXPECT_EQ(a.alphaCutoff, b.alphaCutoff);
  EXPECT_EQ(a.normalScale, b.normalScale);
  EXPECT_EQ(a.occlusionStrength, b.occlusionStrength);
  EXPECT_EQ(a.textures, b.textures);
  for (uint32_t s = 0; s < kTextureSlotCount; ++s) expectSameUv(a.uv[s], b.uv[s]);
  EXPECT_EQ(a.ka, b.ka);
  EXPECT_EQ(a.kd, b.kd);
  EXPECT_EQ(a.ks, b.ks);
  EXPECT_EQ(a.ke, b.ke);
  EXPECT_EQ(a.ns, b.ns);
  EXPECT_EQ(a.mirror, b.mirror);
  EXPECT_EQ(a.ior, b.ior);
  EXPECT_EQ(a.transparency, b.transparency);
}

inline void expectSameMesh(const Mesh& a, const Mesh& b) {
  SCOPED_TRACE("mesh " + a.name);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.normals, b.normals);
  EXPECT_EQ(a.texcoords, b.texcoords);
  EXPECT_EQ(a.texcoords1, b.texcoords1);
  EXPECT_EQ(a.tangents, b.tangents);
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_EQ(a.indices, b.indices);
  if (!a.positions.empty()) {
    EXPECT_EQ(a.bounds.min, b.bounds.min);
    EXPECT_EQ(a.bounds.max, b.bounds.max);
  }
  ASSERT_EQ(a.clusters.size(), b.clusters.size());
  for (size_t k = 0; k < a.clusters.size(); ++k) {
    const Cluster &x = a.clusters[k], &y = b.clusters[k];
    EXPECT_TRUE(x.firstTriangle == y.firstTriangle && x.triangleCount == y.triangleCount && x.center == y.center &&
                x.radius == y.radius && x.coneAxis == y.coneAxis && x.coneCutoff == y.coneCutoff)
        << "cluster " << k;
  }
}

inline void expectSameLight(const Light& a, const Light& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.falloff, b.falloff);
  EXPECT_EQ(a.corner, b.corner);
  EXPECT_EQ(a.edge1, b.edge1);
  EXPECT_EQ(a.edge2, b.edge2);
  EXPECT_EQ(a.normal, b.normal);
  EXPECT_EQ(a.direction, b.direction);
  EXPECT_EQ(a.innerConeCos, b.innerConeCos);
  EXPECT_EQ(a.outerConeCos, b.outerConeCos);
  EXPECT_EQ(a.range, b.range);
}

inline void expectSameScene(const Scene& a, const Scene& b, bool texturePaths = true) {
  ASSERT_EQ(a.textures.size(), b.textures.size());
  for (size_t i = 0; i < a.textures.size(); ++i) {
    const Texture &x = a.textures[i], &y = b.textures[i];
    SCOPED_TRACE("texture " + std::to_string(i));
    if (texturePaths) {
      EXPECT_EQ(x.path, y.path);
      EXPECT_EQ(x.bytes, y.bytes);
    }
    EXPECT_EQ(x.srgb, y.srgb);
    EXPECT_EQ(x.channels, y.channels);
    EXPECT_EQ(x.sourceChannel, y.sourceChannel);
    EXPECT_TRUE(x.sampler == y.sampler);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) expectSameMaterial(a.materials[i], b.materials[i]);
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (size_t i = 0; i < a.meshes.size(); ++i) expectSameMesh(a.meshes[i], b.meshes[i]);
  ASSERT_EQ(a.instances.size(), b.instances.size());
  for (size_t i = 0; i < a.instances.size(); ++i) {
    EXPECT_EQ(a.instances[i].mesh, b.instances[i].mesh) << "instance " << i;
    EXPECT_EQ(a.instances[i].transform, b.instances[i].transform) << "instance " << i;
  }
  ASSERT_EQ(a.defaultView.has_value(), b.defaultView.has_value());
  if (a.defaultView) {
    EXPECT_EQ(a.defaultView->position, b.defaultView->position);
    EXPECT_EQ(a.defaultView->yawDeg, b.defaultView->yawDeg);
    EXPECT_EQ(a.defaultView->pitchDeg, b.defaultView->pitchDeg);
  }
  EXPECT_EQ(a.defaultFovYDeg, b.defaultFovYDeg);
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i) expectSameLight(a.lights[i], b.lights[i]);
}

}  // namespace rtr::test
