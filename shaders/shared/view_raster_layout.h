// The camera view's visibility raster (raster/mesh_view_raster.h, view_visibility_vs.vert): its
// push constants, shared by C++ and GLSL (STYLE.md habit 1).
//
// Clip space is Vulkan's (y down) with reverse-Z and an infinite far plane: clip = (x_c, y_c,
// near, z_view), so depth = near / z_view falls from 1 at the near plane towards 0 far away,
// where float depth keeps its precision (Reed 2015, "Depth Precision Visualized"); the depth
// test keeps the greater value.
#ifndef SDFSTREAM_VIEW_RASTER_LAYOUT_H
#define SDFSTREAM_VIEW_RASTER_LAYOUT_H

#include "shaders/shared/glsl_cpp.h"

SDF_BEGIN_NAMESPACE

struct ViewRasterPush {
  vec4 clipFromWorld[4];  // rows: clip_i = dot(clipFromWorld[i], vec4(world position, 1))
};

// The visibility buffer resolved on the device (raster_resolve.comp, MeshViewRaster::
// recordResolve): the scene's materials and textures in storage buffers, looked up as
// world/triangle_scene.cpp's sampleAlbedo / sampleEmission do with a TexturePyramid (its CPU
// reference, resolvePrimarySurfaces).
struct RasterMaterialGpu {
  vec4 baseColorFactor;  // linear RGBA
  vec4 emissive;         // rgb linear; w unused
  ivec4 textures;        // x: base colour texture (-1: none), y: its UV set (0/1; other: none),
                         // z: emissive texture, w: its UV set
  vec4 baseUv;           // the base colour tap's UV transform: column0.xy, column1.xy
  vec4 emissiveUv;       // the emissive tap's: column0.xy, column1.xy
  vec4 uvOffsets;        // xy: base colour offset, zw: emissive offset
};

// A texture: levels[first .. first + count) of RasterLevelGpu (level 0 the texture itself).
// count 0: not a usable image (white, as sampleTexture treats it).
struct RasterTextureGpu {
  uvec4 levels;  // x: first level, y: level count, zw unused
};
struct RasterLevelGpu {
  uvec4 info;  // x: first texel (RGBA8 sRGB words of the texel buffer), y: width, z: height
};

struct RasterResolvePush {
  vec4 eye;          // xyz: the camera, world space; w: the pixel's angle (radians)
  vec4 stackOrigin;  // xyz: the stack frame's origin, world space; w: 1 / voxel size
  uvec4 size;        // x: width, y: height, z: triangles, w: bit 0 UV set 0 present, bit 1 set 1
};

SDF_END_NAMESPACE

#ifdef __cplusplus
static_assert(sizeof(sdfstream::gpu_shared::ViewRasterPush) == 64);
static_assert(sizeof(sdfstream::gpu_shared::RasterMaterialGpu) == 96);
static_assert(sizeof(sdfstream::gpu_shared::RasterResolvePush) == 48);
#endif

#endif
