#version 460
// Buffer references that lead back to their own block (a linked list), arrays of them, and a push-constant
// block that ends in an array of references.
#extension GL_EXT_buffer_reference : require
layout(local_size_x = 1) in;
layout(buffer_reference) buffer Node;
layout(buffer_reference, std430) buffer Node { vec4 value; Node next; };
layout(buffer_reference, std430) buffer Tail { uint count; float data[]; };
layout(set = 0, binding = 0, std430) buffer Roots { Node head; Node heads[4]; Tail tail; uint n; } roots;
layout(push_constant) uniform Push { uint k; Node ring[2]; } pc;
void main() {
  Node node = pc.ring[0];
  float s = 0;
  for (uint i = 0; i < pc.k; ++i) { s += node.value.x; node = node.next; }
  roots.n = uint(s) + roots.tail.count;
  roots.heads[1] = roots.head;
}
