// Runs the same particle step with the original class, Particles_CPU (all cores) and
// Particles_Vulkan (the default Vulkan device), compares results and prints a table of times.
#include "Particles.h"
#include "Particles_CPU.h"
#ifdef CROSSRT_HAS_ISPC
#include "Particles_ISPC.h"
#endif
#include "Particles_Vulkan.h"

#include "CommandLine.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

using LiteMath::float4;

struct Run
{
  const char* name;
  std::vector<float4> pos, vel;
  std::shared_ptr<Particles> impl;
  float ms = 0.0f;
  float parts[3] = {0.0f, 0.0f, 0.0f};  // GPU time, copy in, copy out (generated classes)
};

int main(int argc, char** argv)
{
  int n = 1 << 20, steps = 10;
  crossrt::CommandLine app("particles",
                           "Moves N particles STEPS times with the original class, Particles_CPU, Particles_ISPC (where built)\n"
                           "and Particles_Vulkan, and prints a table of times. Exits non-zero when their results differ.");
  app.add_option("N", n, "particles")->check(crossrt::Positive());
  app.add_option("STEPS", steps, "steps")->check(crossrt::NonNegative());
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float4> pos(n), vel(n);
  for (int i = 0; i < n; ++i)
  {
    pos[i] = float4(u(rng) * 10.0f, 5.0f + u(rng) * 5.0f, u(rng) * 10.0f, 0.0f);
    vel[i] = float4(u(rng), u(rng) * 3.0f, u(rng), 0.0f);
  }

  std::vector<Run> runs;
  runs.push_back({"original (1 thread)", pos, vel, std::make_shared<Particles>()});
  runs.push_back({"Particles_CPU (all cores)", pos, vel, CreateParticles_CPU()});
#ifdef CROSSRT_HAS_ISPC
  runs.push_back({"Particles_ISPC", pos, vel, CreateParticles_ISPC()});
#endif
  try
  {
    runs.push_back({"Particles_Vulkan", pos, vel, CreateParticles_Vulkan()});
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "Vulkan unavailable: %s\n", e.what());
  }

  for (auto& r : runs)
  {
    try
    {
      r.impl->CommitDeviceData();
      for (int s = 0; s < steps; ++s)
      {
        r.impl->Step(n, 0.01f, r.pos.data(), r.vel.data());
        float t[4];
        r.impl->GetExecutionTime("Step", t);
        r.ms += t[3];
        for (int k = 0; k < 3; ++k) r.parts[k] += t[k];
      }
    }
    catch (const std::exception& e)  // a device lost, an ISPC target this CPU cannot run
    {
      std::fprintf(stderr, "particles: error: %s: %s\n", r.name, e.what());
      return 1;
    }
  }

  std::printf("%d particles, %d steps\n\n", n, steps);
  std::printf("| %-24s | %10s | %8s | %-40s | %12s | %8s |\n", "implementation", "ms/step", "speedup", "bounding box", "energy", "bounces");
  std::printf("|%s|\n", std::string(121, '-').c_str());
  for (auto& r : runs)
  {
    const Particles& p = *r.impl;
    char box[96];
    std::snprintf(box, sizeof box, "(%.3f %.3f %.3f)-(%.3f %.3f %.3f)", p.m_boxMin.x, p.m_boxMin.y, p.m_boxMin.z, p.m_boxMax.x, p.m_boxMax.y, p.m_boxMax.z);
    std::printf("| %-24s | %10.3f | %7.2fx | %-40s | %12.1f | %8d |\n", r.name, r.ms / steps, runs[0].ms / r.ms, box, p.m_kineticEnergy, p.m_bounces);
  }
  for (auto& r : runs)
    if (r.parts[0] > 0.0f)
      std::printf("%s: GPU %.3f ms, copy in %.3f ms, copy out %.3f ms per step\n", r.name, r.parts[0] / steps, r.parts[1] / steps, r.parts[2] / steps);
  // The implementations must agree: positions within a relative 1e-4 of the original.
  double worst = 0.0;  // a NaN stays (std::max would drop it, and the check below would pass)
  for (size_t k = 1; k < runs.size(); ++k)
    for (int i = 0; i < n; ++i)
      if (const double d = LiteMath::length(runs[k].pos[i] - runs[0].pos[i]); std::isnan(d) || d > worst) worst = d;
  std::printf("\nlargest position difference from the original: %.3g\n", worst);
  // And the reductions: the same bounces and box, and sums within what float rounding allows. Each
  // class adds in its own order (the original one by one, the others in chunks and trees), so a sum may
  // be off by a small part of the sum of its terms' magnitudes, measured here in double.
  bool agree = worst < 1e-3;
  const Particles& original = *runs[0].impl;
  double magnitude[3] = {0.0, 0.0, 0.0};
  for (const float4& v : runs[0].vel)
    for (int c = 0; c < 3; ++c) magnitude[c] += std::abs(double(v[c]));
  const float momentumTolerance = float(1e-4 * std::sqrt(magnitude[0] * magnitude[0] + magnitude[1] * magnitude[1] + magnitude[2] * magnitude[2]));
  for (size_t k = 1; k < runs.size(); ++k)
  {
    const Particles& p = *runs[k].impl;
    const bool same = p.m_bounces == original.m_bounces && LiteMath::length(p.m_boxMin - original.m_boxMin) < 1e-3f &&
                      LiteMath::length(p.m_boxMax - original.m_boxMax) < 1e-3f &&
                      std::abs(p.m_kineticEnergy - original.m_kineticEnergy) <= 1e-4f * std::abs(original.m_kineticEnergy) &&
                      LiteMath::length(p.m_momentum - original.m_momentum) <= momentumTolerance;
    if (!same)
      std::printf("%s: its reductions differ from the original's: bounces %d (%d), energy %.7g (%.7g), momentum off by %.3g (allowed %.3g)\n",
                  runs[k].name, p.m_bounces, original.m_bounces, p.m_kineticEnergy, original.m_kineticEnergy,
                  LiteMath::length(p.m_momentum - original.m_momentum), momentumTolerance);
    agree = agree && same;
  }
  return agree ? 0 : 1;
}
