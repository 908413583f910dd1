// The compute rasteriser's constants and push block, shared by render/raster.cpp and its shaders
// (docs/raster.md). Visibility buffer: one uint64 per pixel, (floatBitsToUint(depth) << 32) | id, id as in
// frame.h (the instance's first id + primitive); RASTER_CLEAR (id VIS_EMPTY) where nothing was drawn.
#ifndef RTR_SHADERS_SHARED_RASTER_H
#define RTR_SHADERS_SHARED_RASTER_H

#include "shared.h"
#ifdef __cplusplus
#include <cstdint>
namespace rtr::shader {
typedef uint32_t uint;
using glm::ivec4;
using glm::vec4;
#endif

#define RASTER_GROUP 128         // raster.comp: one workgroup per cluster, a thread per triangle
#define RASTER_CLEAR_GROUP 256   // raster_clear.comp: a thread per pixel
#define RASTER_SUBPIXEL_BITS 8   // fixed-point vertex positions: 1/256 pixel
#define RASTER_GUARD_BAND 16384.0 // px from the image centre; beyond it (or w <= 0) the hardware draws it
#define RASTER_SHARED_AREA 256u  // default: bounding boxes over this many pixels are rasterised tile by tile
// Medium triangles: a small one whose box is over RASTER_MEDIUM_FROM pixels (raster.comp's kMediumFrom;
// RTR_RASTER_MEDIUM) is set up in a record and drawn by raster_large.comp, not by its own thread (whose
// subgroup would wait for it): a box of up to RASTER_MEDIUM_NARROW_AREA pixels by RASTER_MEDIUM_NARROW_LANES
// threads (two triangles a 32-lane subgroup; raster.comp's kMediumNarrow, RTR_RASTER_MEDIUM_LANES), a larger
// one by RASTER_MEDIUM_LANES. The two kinds share the list from its two ends (RasterPush::mediumCapacity
// records: the scene's triangles, at most RASTER_MEDIUM_TRIANGLES); a subgroup whose records do not all fit
// draws its medium triangles itself.
#define RASTER_MEDIUM_FROM 32u
#define RASTER_MEDIUM_TRIANGLES (1u << 18)
#define RASTER_MEDIUM_LANES 32u
#define RASTER_MEDIUM_NARROW_LANES 16u
#define RASTER_MEDIUM_NARROW_AREA 64u
#define RASTER_TILE 32           // raster_large.comp: a workgroup per tile of RASTER_TILE² pixels of a triangle
#define RASTER_LARGE_CAPACITY (1u << 20)  // tiles in the list; a triangle that does not fit goes to the hardware
#define RASTER_LARGE_TRIANGLES (1u << 17) // large triangles' records a frame; one that does not fit goes to the hardware
#define RASTER_LARGE_GROUPS 1024u         // raster_large.comp's persistent workgroups
// RTR_RASTER_MEASURE (render/raster.cpp; raster_tri.glsl's kMeasure): raster.comp without its atomics or
// its pixel loop, to split its time. Measuring only: the ids are then wrong.
#define RASTER_MEASURE_OFF 0u
#define RASTER_MEASURE_NO_ATOMICS 1u
#define RASTER_MEASURE_SETUP 2u
#define RASTER_LOCAL_BITS 7u     // hand-off and tile entries: position in the cluster list << RASTER_LOCAL_BITS | triangle
// Hand-off list entries at most (64 MiB): the near-plane and guard-band triangles of a frame, not every
// triangle of a billion-triangle scene (a storage buffer's range is 4 GiB at most on many devices). Past
// it, triangles are dropped and counted (ComputeRaster::handOffTriangles, which rtr-view prints).
#define RASTER_HANDOFF_CAPACITY (1u << 24)

// raster_clip.comp: a workgroup of RASTER_CLIP_THREADS per listed triangle (crossing the near plane or the
// guard band; raster.comp counts the indirect dispatch's x by RASTER_CLIP_GROUP entries) and fan piece (y).
#define RASTER_CLIP_GROUP 1u
#define RASTER_CLIP_THREADS 128
#define RASTER_CLIP_PIECES 6u             // a triangle clipped by five planes has at most 8 vertices
#define RASTER_CLIP_CAPACITY 65535u       // its list's entries (a dispatch's x); past them a triangle goes to the hardware
// The clipping planes' distance from the image centre in pixels: inside the guard band, so that a clipped
// vertex's rounding never takes it out again.
#define RASTER_CLIP_BAND (RASTER_GUARD_BAND - 64.0)

// A large triangle as raster.comp set it up (raster_tri.glsl's Tri, less what follows from it), written
// once for raster_large.comp's tiles: a tile reads it instead of fetching and transforming the triangle.
struct RasterLargeTri {
  ivec4 box;   // pixels whose centres lie in the snapped bounding box (min x, min y, max x, max y)
  ivec4 v01;   // fixed-point vertices 0 and 1, ordered so that the edge functions are positive inside
  ivec4 v2;    // vertex 2 (x, y); z: the id; w: the alpha test's material (NO_TEXTURE: none)
  vec4 z;      // depth (z/w) at the vertices
  vec4 invW;   // the alpha test only: 1/w at the vertices,
  vec4 uv01;   // the mask's texcoords at vertices 0 and 1,
  vec4 uv2;    // and at vertex 2
};

struct RasterPush {
  uint width;
  uint height;
  uint clusterCount;
  uint fromList;       // raster.comp: clusters from the culling pass's visible list, not all of them
  uint handOffCapacity;  // entries of the hand-off list (at most RASTER_HANDOFF_CAPACITY)
  uint clip;  // raster.comp: triangles crossing w = 0 or the guard band to raster_clip.comp, not the hardware
  uint mediumCapacity;  // the medium triangles' records (at most RASTER_MEDIUM_TRIANGLES unless measuring)
  uint pad2;
};

#ifdef __cplusplus
}  // namespace rtr::shader
#endif
#endif
