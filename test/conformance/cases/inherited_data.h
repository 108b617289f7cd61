// Data members and a std::vector of a base class read in the derived class's kernel (kernel_slicer's 034).
#pragma once
#include "LiteMath.h"
#include <vector>

class BaseBlend
{
public:
  BaseBlend() : vInBase(16) {}
  virtual ~BaseBlend() = default;
  virtual void Test(float* a_data [[size("a_size")]], unsigned int a_size);
  virtual void CommitDeviceData() {}

protected:
  virtual void kernel1D_Test(float* a_data, unsigned int a_size);
  float dataInBaseClass = 2.0f;
  std::vector<float> vInBase;
};

class DerivedBlend : public BaseBlend
{
public:
  DerivedBlend() : vInDerived(16) {}
  void Init();

protected:
  void kernel1D_Test(float* a_data, unsigned int a_size) override;
  float dataInDerivedClass = 0.5f;
  std::vector<float> vInDerived;
};
