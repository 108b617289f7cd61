#include "particle_refs.h"

#include <algorithm>
#include <cmath>
#include <utility>

ParticleRefs::ParticleRefs()
{
  for (uint32_t i = 0; i < 200; i++)
  {
    Body b;
    b.pos = LiteMath::float3(std::sin(0.1f * float(i)), std::cos(0.13f * float(i)), 0.01f * float(i));
    b.mass = 1.0f + 0.01f * float(i);
    b.vel = LiteMath::float3(0.0f, 0.1f, -0.05f);
    b.age = 0.0f;
    m_bodies.push_back(b);
  }
}

void ParticleRefs::Advance(uint32_t n, float dt) { kernel1D_Advance(n, dt); }

void ParticleRefs::kernel1D_Advance(uint32_t n, float dt)
{
  for (uint32_t i = 0; i < n; i++)
  {
    std::vector<Body>& all = m_bodies;
    Body& b = all[i];
    assert(b.mass > 0.0f && "bodies have mass");
    float lo = b.pos.x, hi = b.pos.y;
    if (lo > hi)
      std::swap(lo, hi);
    std::array<float, 3> weights = {0.25f, 0.5f, 0.25f};
    std::array<float, 2> acc{};
    for (float w : weights)
      acc[0] += w * (hi - lo) / float(weights.size());
    const std::array<float, 3> copy = weights;
    acc[1] = copy[1];
    float steps[2] = {dt, 0.5f * dt};
    float& last = steps[1];
    last *= 1.0f + acc[0];
    LiteMath::float3& v = b.vel;
    v += LiteMath::float3(0.0f, -9.8f, 0.0f) * steps[0] / b.mass;
    b.pos += v * last;
    b.age += dt + acc[1] + 0.01f * std::max({lo, hi, 0.0f}) - 0.001f * std::min({hi, lo});
  }
}
