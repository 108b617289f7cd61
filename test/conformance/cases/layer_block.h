// A ...Block control function that passes the per-thread function a constant for a parameter that
// function's loop reads, while having a parameter of that name itself (kernel_slicer's
// StupidPathTraceBlock calls StupidPathTrace(i, 6, ...) with its own a_maxDepth unused): the loop
// runs 3 times, whatever a_layers the Block was given. Its per-thread local starts at a value
// (float amount = 1.5f;), which the wavefront form fills its buffer with.
#pragma once
#include <cstdint>

class LayerBlock
{
public:
  virtual void AddBlock(uint32_t n, uint32_t a_layers, float* out [[size("n")]]);
  virtual void CommitDeviceData() {}

  // kernel_slicer's test 051: the size is on the per-thread function, in its thread id's name
  // (the count of the Block's loop that passes it).
  virtual void QuarterBlock(float* out, uint32_t a_count);
  void Quarter(float* out [[size("tid")]], uint32_t tid);

  void Add(uint32_t tid, uint32_t a_layers, float* out);  // one thread's work
  void kernel_AddOne(uint32_t tid, float* amount, float* out);
  void kernel_Halve(uint32_t tid, float* out);
};
