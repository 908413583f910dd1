// Push constants and limits of the mip shaders (shaders/render/mips.comp, mips_even.comp), shared by
// GLSL and C++ (src/render/mips.cpp). Plain ints only, so the std430 push block is the C++ layout.
#ifndef RTR_SHADERS_SHARED_MIPS_H
#define RTR_SHADERS_SHARED_MIPS_H

#ifdef __cplusplus
namespace rtr::shader {
#endif

#define MIP_MAX_LEVELS_PER_DISPATCH 6  // levels one dispatch writes (64x64 -> 1x1)
#define MIP_GROUP_SIZE 256             // threads of a workgroup (both shaders)
#define MIP_EVEN_TILE 64               // mips_even.comp: source texels per workgroup and axis
// mips.comp: side of the shared-memory tiles holding a dispatch's odd (1st, 3rd, 5th) and even output
// levels. 64x64 source texels give 32x32; the margin takes the extra texels of odd sizes (the host plan
// checks every workgroup's footprint against these and writes fewer levels per dispatch when needed).
#define MIP_CAP_ODD 36
#define MIP_CAP_EVEN 20

struct MipPush {
  int srcWidth;     // size of the source level of this dispatch
  int srcHeight;
  int levels;       // levels written (1 .. MIP_MAX_LEVELS_PER_DISPATCH)
  int srgb;         // 1: sRGB-encode R, G, B on write (alpha stays linear)
  int fromScratch;  // 1: the source level is the float copy the previous dispatch left (not level 0)
};

#ifdef __cplusplus
}  // namespace rtr::shader
#endif

#endif
