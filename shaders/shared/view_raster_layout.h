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

SDF_END_NAMESPACE

#ifdef __cplusplus
static_assert(sizeof(sdfstream::gpu_shared::ViewRasterPush) == 64);
#endif

#endif
