// A control function that is not virtual (kernel_slicer allows it: it then only gets ...Cmd).
#pragma once
#include "LiteMath.h"

class Accumulate
{
public:
  void AddInto(int n, const float* a_in __attribute__((size("n"))), float* a_acc __attribute__((size("n"))));
  virtual void GetExecutionTime(const char* a_funcName, float a_out[4]);

protected:
  void kernel1D_Add(int n, const float* a_in, float* a_acc);
};
