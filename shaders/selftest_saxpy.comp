// y[i] = a * x[i] + y[i]: the gpu module's self-test kernel (tests/gpu). Exercises two storage
// buffers, push constants, a partial last workgroup and specialization constant 0 (true:
// y[i] = y[i] - a * x[i]; gpu::ComputePipelinePair). `precise` forbids fusing into an FMA so
// the result matches the CPU reference bit for bit (the C++ side builds with -ffp-contract=off).
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

layout(std430, set = 0, binding = 0) readonly buffer X { float x[]; };
layout(std430, set = 0, binding = 1) buffer Y { float y[]; };

layout(push_constant) uniform Push {
  float a;
  uint count;
} pc;

layout(constant_id = 0) const bool kSubtract = false;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  precise float ax = pc.a * x[i];
  precise float r = kSubtract ? y[i] - ax : ax + y[i];
  y[i] = r;
}
