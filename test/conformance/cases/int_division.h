// Integer division and remainder as users write them: by a divisor that differs per thread, by a
// member every thread shares, by a constant and by an expression of the thread's index; signed with
// negative operands (C++ truncates towards zero, and % takes the dividend's sign) and unsigned above
// 2^31.
#pragma once
#include "LiteMath.h"
#include <cstdint>

using LiteMath::int4;
using LiteMath::uint4;

class IntDivision
{
public:
  IntDivision() = default;
  virtual ~IntDivision() = default;
  virtual void Divide(int n, const int* a [[size("n")]], const int* b [[size("n")]], const uint32_t* u [[size("n")]], int4* quotients [[size("n")]],
                      uint4* unsignedQuotients [[size("n")]]);
  virtual void SetStep(int step) { m_step = step; }
  virtual void CommitDeviceData() {}

protected:
  void kernel1D_Divide(int n, const int* a, const int* b, const uint32_t* u, int4* quotients, uint4* unsignedQuotients);

  int m_step = 7;  // a divisor all threads share
};
