// Runs Heat as written, as Heat_CPU and as Heat_Vulkan; exits 0 only when they agree.
#include "Heat_CPU.h"
#include "Heat_Vulkan.h"

#include <cmath>
#include <cstdio>
#include <vector>

int main()
{
  const int w = 96, h = 64;
  std::vector<float> start(w * h, 0.0f);
  for (int y = 20; y < 40; ++y)
    for (int x = 30; x < 60; ++x) start[y * w + x] = 10.0f;
  std::shared_ptr<Heat> impls[3] = {std::make_shared<Heat>(w, h), CreateHeat_CPU(w, h), CreateHeat_Vulkan(w, h)};
  std::vector<float> results[3];
  for (int k = 0; k < 3; ++k)
  {
    results[k] = start;
    impls[k]->CommitDeviceData();
    impls[k]->Diffuse(20, results[k].data());
  }
  float worst = 0.0f;
  for (int k = 1; k < 3; ++k)
    for (int i = 0; i < w * h; ++i) worst = std::max(worst, std::fabs(results[k][i] - results[0][i]));
  std::printf("total heat: original %.3f, CPU %.3f, Vulkan %.3f; largest cell difference %.3g\n",
              impls[0]->m_total, impls[1]->m_total, impls[2]->m_total, worst);
  const bool ok = worst < 1e-4f && std::fabs(impls[2]->m_total - impls[0]->m_total) < 1e-2f && impls[0]->m_total > 5999.0f;
  std::printf(ok ? "OK\n" : "MISMATCH\n");
  return ok ? 0 : 1;
}
