// The hyperbolic functions as a network's activations use them (kernel_slicer's apps call tanh in
// kernels): tanh, sinh, cosh and their inverses over a range of inputs, zero and the tails too.
#pragma once
#include <cstdint>

class Activations
{
public:
  Activations() {}
  virtual ~Activations() {}
  virtual void CommitDeviceData() {}
  // a_out[6 * i + k]: the k-th function of a_in[i].
  virtual void Apply(const float* a_in [[size("n")]], float* a_out [[size("6 * n")]], int n);

protected:
  void kernel1D_Apply(const float* a_in, float* a_out, int n);
};
