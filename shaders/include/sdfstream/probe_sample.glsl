// sdfstream's probe field sampled from an engine's own shader: irradiance(x, n, view) of the DDGI
// probes (one volume per SDF cascade) with no CPU round trip. The math is the library's own
// (shaders/probe_sample.glsl, which ProbeField::sample and the CPU reference also compile), so
// the engine gets the same values (bit for bit: tests/probes/probe_sample_include_test.cpp).
//
// Use (GLSL 4.50, Vulkan; the includer enables GL_GOOGLE_include_directive):
//   #define SDFSTREAM_PROBE_SET 0      // optional: descriptor set (default 0)
//   #define SDFSTREAM_PROBE_BINDING 3  // optional: first binding (default 0)
//   #include "sdfstream/probe_sample.glsl"
//   ... vec3 e = sdfstreamIrradianceWorld(worldPos, n, toCamera);
// Include path: the installed include/. This file's own "shaders/..." includes sit below its
// folder, include/sdfstream/, which glslang searches for every file of the include chain; with a
// compiler that searches only the including file's folder, add include/sdfstream too. In the
// source tree: -I shaders/include -I <repository root>.
//
// Descriptors: set SDFSTREAM_PROBE_SET, binding SDFSTREAM_PROBE_BINDING + k, std430 storage
// buffers, read only, holding the library's own structs (shaders/shared/*.h):
//   k  block                     contents                        host buffer (own pass binding)
//   0  SdfstreamProbeFrame       ProbeFrame, one                 ProbeField frame (0)
//   1  SdfstreamProbeVolumes     ProbeVolume per cascade         ProbeField volumes (1)
//   2  SdfstreamProbeData        vec4 per probe: offset, state   ProbeField data (2)
//   3  SdfstreamProbeIrradiance  vec4 per irradiance texel       ProbeField irradiance (4)
//   4  SdfstreamProbeDepth       vec2 per depth texel            ProbeField depth (5)
//   5  SdfstreamPageTable        uint per page, all cascades     GpuStackScene pageTables (12)
//   6  SdfstreamDistanceAtlas    uint: two fp16 distances        GpuStackScene distance (13)
//   7  SdfstreamCascades         CascadeTraceParams per cascade  GpuStackScene params (16)
// The variables are sdfstreamProbeFrame, sdfstreamProbeVolumes[], ... sdfstreamCascades[]; the
// bindings in parentheses are those of the library's own passes (shaders/probe_bindings.glsl). 5-7
// serve the SDF visibility test (SDFDDGI Sec. 4.2). All must hold the same frame: the field's
// buffers after its update, the stack scene synced to the stack that update saw.
//
// Functions:
//   vec3 sdfstreamIrradiance(vec3 x, vec3 n, vec3 view)
//     x in the probe field's own coordinates: cascade-0 voxels relative to cascade 0's minimum
//     corner (CascadeStackImage::toStack, as GiSystem::irradiance queries take); n the unit
//     surface normal; view the unit direction from x towards the camera.
//   vec3 sdfstreamIrradianceWorld(vec3 worldPos, vec3 n, vec3 view)
//     the same at a world position (metres), through ProbeFrame::worldToStack of the frame.
//
// Names this file adds to the includer's shader: the SDFSTREAM_* macros and the SDF_* helper
// macros of the shared files (SDF_CONST, SDF_PRECISE, ...), the shared structs and constants
// (ProbeFrame, ProbeVolume, ProbeQuery, CascadeTraceParams, k*), the sdf* / probe* functions and
// their result structs; the storage macros the math reads are #undef'd again at the end.
#ifndef SDFSTREAM_PROBE_SAMPLE_GLSL
#define SDFSTREAM_PROBE_SAMPLE_GLSL

#ifndef SDFSTREAM_PROBE_SET
#define SDFSTREAM_PROBE_SET 0
#endif
#ifndef SDFSTREAM_PROBE_BINDING
#define SDFSTREAM_PROBE_BINDING 0
#endif

#include "shaders/shared/sdf_layout.h"
#include "shaders/shared/probe_layout.h"

// Buffer k of the table above.
#define SDFSTREAM_PROBE_BUFFER(k, Block, member)                                              \
  layout(std430, set = SDFSTREAM_PROBE_SET, binding = SDFSTREAM_PROBE_BINDING + k) readonly \
      buffer Block {                                                                          \
    member;                                                                                   \
  }
SDFSTREAM_PROBE_BUFFER(0, SdfstreamProbeFrame, ProbeFrame sdfstreamProbeFrame);
SDFSTREAM_PROBE_BUFFER(1, SdfstreamProbeVolumes, ProbeVolume sdfstreamProbeVolumes[]);
SDFSTREAM_PROBE_BUFFER(2, SdfstreamProbeData, vec4 sdfstreamProbeData[]);
SDFSTREAM_PROBE_BUFFER(3, SdfstreamProbeIrradiance, vec4 sdfstreamProbeIrradiance[]);
SDFSTREAM_PROBE_BUFFER(4, SdfstreamProbeDepth, vec2 sdfstreamProbeDepth[]);
SDFSTREAM_PROBE_BUFFER(5, SdfstreamPageTable, uint sdfstreamPageTable[]);
SDFSTREAM_PROBE_BUFFER(6, SdfstreamDistanceAtlas, uint sdfstreamDistanceAtlas[]);
SDFSTREAM_PROBE_BUFFER(7, SdfstreamCascades, CascadeTraceParams sdfstreamCascades[]);
#undef SDFSTREAM_PROBE_BUFFER

// The storage macros of the math below (shaders/probe_field_storage.glsl defines the same names
// for the library's passes). Sampling reads nothing else: no albedo, emission or light cache.
#define SDF_PAGE(i) sdfstreamPageTable[i]
#define SDF_DIST_WORD(i) sdfstreamDistanceAtlas[i]
#define SDF_CASCADE(c) sdfstreamCascades[c]
#define PROBE_VOLUME(c) sdfstreamProbeVolumes[c]
#define PROBE_DATA(g) sdfstreamProbeData[g]
#define PROBE_IRRADIANCE(i) sdfstreamProbeIrradiance[i]
#define PROBE_DEPTH(i) sdfstreamProbeDepth[i]
#include "shaders/sdf_trace.glsl"
#include "shaders/probe_math.glsl"
#include "shaders/probe_update.glsl"
#include "shaders/probe_field.glsl"
#include "shaders/probe_sample.glsl"
#undef SDF_PAGE
#undef SDF_DIST_WORD
#undef SDF_CASCADE
#undef PROBE_VOLUME
#undef PROBE_DATA
#undef PROBE_IRRADIANCE
#undef PROBE_DEPTH

// irradiance(x, n, view) of the field, all cascades blended, with the frame's visibility options
// (the queries of ProbeField::sample with position.w = 0).
vec3 sdfstreamIrradiance(vec3 x, vec3 n, vec3 view) {
  return probeFieldIrradiance(sdfstreamProbeFrame, x, n, view, true, -1);
}

// The same at a world position in metres: x = (worldPos - corner) / voxel size, with
// worldToStack = (cascade 0's minimum corner, 1 / cascade-0 voxel size) of the frame (float:
// about a millimetre of rounding 10 km from the origin).
vec3 sdfstreamIrradianceWorld(vec3 worldPos, vec3 n, vec3 view) {
  vec4 w = sdfstreamProbeFrame.worldToStack;
  return sdfstreamIrradiance((worldPos - w.xyz) * w.w, n, view);
}

#endif  // SDFSTREAM_PROBE_SAMPLE_GLSL
