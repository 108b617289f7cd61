// Everyday C++ in a kernel: a reference to a member vector and one to the thread's element of it
// (written through), a reference to a local array's element, assert, std::swap, std::min/max of a
// braced list, and std::array (braces, value-initialised, copied, size(), a range-for over it).
#pragma once
#include "LiteMath.h"
#include <array>
#include <cassert>
#include <cstdint>
#include <vector>

struct Body
{
  LiteMath::float3 pos;
  float mass;
  LiteMath::float3 vel;
  float age;
};

class ParticleRefs
{
public:
  ParticleRefs();
  virtual ~ParticleRefs() = default;
  virtual void Advance(uint32_t n, float dt);
  virtual void CommitDeviceData() {}
  std::vector<Body> m_bodies;

protected:
  void kernel1D_Advance(uint32_t n, float dt);
};
