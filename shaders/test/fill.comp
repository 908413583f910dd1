#version 460
// Test kernel: out[i] = i * i + offset, for the headless compute smoke test.
layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) writeonly buffer Output { uint values[]; } outBuf;
layout(push_constant) uniform Push { uint count; uint offset; } pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) outBuf.values[i] = i * i + pc.offset;
}
