// Runs Heat and RayCaster as written, as <Class>_CPU and as <Class>_Vulkan; exits 0 only when they
// agree (and RayCaster's image shows what the scene holds).
#include "Heat_CPU.h"
#include "Heat_Vulkan.h"
#include "RayCaster_CPU.h"
#include "RayCaster_Vulkan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace
{
// A unit cube around the origin: 8 corners, 12 triangles.
const float kCubeVerts[] = {-0.5f, -0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, -0.5f, -0.5f, 0.5f, -0.5f,
                            -0.5f, -0.5f, 0.5f,  0.5f, -0.5f, 0.5f,  0.5f, 0.5f, 0.5f,  -0.5f, 0.5f, 0.5f};
const uint32_t kCubeIndices[] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5};

struct Frame
{
  std::vector<uint32_t> color;
  std::vector<float> depth, sorted;
  std::vector<uint32_t> rowOffsets;
  uint32_t hits = 0, sortedCount = 0;
  float meanDepth = 0.0f, maxDepth = 0.0f;
};

// Two cubes, one rotated, in front of a camera at z = 3; renders and sorts the depths.
Frame RenderCubes(std::shared_ptr<RayCaster> caster, int w, int h)
{
  std::shared_ptr<ISceneObject> scene(CreateSceneRT("sah"), DeleteSceneRT);
  const uint32_t cube = scene->AddGeom_Triangles3f(kCubeVerts, 8, kCubeIndices, 36);
  scene->AddInstance(cube, LiteMath::translate4x4(float3(-0.6f, 0.0f, 0.0f)));
  scene->AddInstance(cube, LiteMath::translate4x4(float3(0.7f, 0.2f, -1.0f)) * LiteMath::rotate4x4Y(0.6f));
  scene->CommitScene();
  caster->SetScene(scene);
  caster->SetCamera(float3(0.0f, 0.0f, 3.0f), 60.0f);
  caster->CommitDeviceData();
  Frame f;
  f.color.resize(size_t(w) * h);
  f.depth.resize(size_t(w) * h);
  f.sorted.resize(size_t(w) * h);
  caster->Render(f.color.data(), f.depth.data());
  caster->SortedDepths(f.sorted.data(), &f.sortedCount);
  f.rowOffsets.resize(size_t(h));
  caster->RowOffsets(f.depth.data(), f.rowOffsets.data());
  f.hits = caster->m_hitCount;
  f.meanDepth = caster->m_meanDepth;
  f.maxDepth = caster->m_maxDepth;
  return f;
}

// RayCaster as written, on all cores and on the GPU: the same pixels (a ray may graze an edge
// differently on the GPU), the same statistics, the hit depths sorted.
bool CheckRayCaster()
{
  const int w = 80, h = 60;
  const Frame ref = RenderCubes(std::make_shared<RayCaster>(w, h), w, h);
  const Frame cpu = RenderCubes(CreateRayCaster_CPU(w, h), w, h);
  const Frame gpu = RenderCubes(CreateRayCaster_Vulkan(w, h), w, h);
  bool ok = true;
  auto check = [&](bool cond, const char* what) {
    if (!cond) std::printf("RayCaster: %s\n", what);
    ok = ok && cond;
  };
  // What the scene holds: the front cube's face at z = 0.5 is 2.5 from the camera, and the cubes
  // cover part of the image, not all of it.
  const float nearest = *std::min_element(ref.sorted.begin(), ref.sorted.begin() + ref.sortedCount);
  check(ref.hits > uint32_t(w * h / 20) && ref.hits < uint32_t(w * h / 2), "the cubes should cover 5-50% of the image");
  check(std::fabs(nearest - 2.5f) < 0.05f, "the nearest depth should be about 2.5");
  check(ref.meanDepth > 2.4f && ref.meanDepth < ref.maxDepth && ref.maxDepth < 4.5f, "depth statistics out of range");
  check(ref.sortedCount == ref.hits && std::is_sorted(ref.sorted.begin(), ref.sorted.begin() + ref.sortedCount), "SortedDepths");
  // The row offsets, counted here from the depths.
  uint32_t above = 0;
  bool offsetsOk = true;
  for (int y = 0; y < h; ++y)
  {
    offsetsOk = offsetsOk && ref.rowOffsets[size_t(y)] == above;
    for (int x = 0; x < w; ++x) above += ref.depth[size_t(y * w + x)] > 0.0f;
  }
  check(offsetsOk && above == ref.hits, "RowOffsets should be the exclusive scan of the rows' hits");
  // Both shades show: the flat cube's colour and the striped cube's.
  std::vector<uint32_t> colours(ref.color);
  std::sort(colours.begin(), colours.end());
  check(std::unique(colours.begin(), colours.end()) - colours.begin() > 8, "the two shades should give many colours");
  for (const Frame* f : {&cpu, &gpu})
  {
    const bool exact = f == &cpu;
    size_t differ = 0;
    float worst = 0.0f;
    for (size_t i = 0; i < ref.color.size(); ++i)
    {
      if ((ref.depth[i] > 0.0f) != (f->depth[i] > 0.0f)) { ++differ; continue; }
      differ += ref.color[i] != f->color[i];
      worst = std::max(worst, std::fabs(ref.depth[i] - f->depth[i]));
    }
    std::printf("RayCaster %s: %u hits (original %u), mean depth %.4f (%.4f), max %.4f (%.4f), %zu pixels differ, depth within %.2g\n",
                exact ? "CPU" : "Vulkan", f->hits, ref.hits, f->meanDepth, ref.meanDepth, f->maxDepth, ref.maxDepth, differ, worst);
    const size_t allowed = exact ? 0 : ref.color.size() / 200;
    check(differ <= allowed && worst < 1e-4f, "pixels differ from the original");
    check(std::abs(int(f->hits) - int(ref.hits)) <= int(allowed), "hit count differs");
    check(std::fabs(f->meanDepth - ref.meanDepth) < 1e-3f && std::fabs(f->maxDepth - ref.maxDepth) < 1e-4f, "depth statistics differ");
    check(f->sortedCount == f->hits && std::is_sorted(f->sorted.begin(), f->sorted.begin() + f->sortedCount), "sorted depths");
    int offsetDiff = 0;
    for (int y = 0; y < h; ++y) offsetDiff = std::max(offsetDiff, std::abs(int(f->rowOffsets[size_t(y)]) - int(ref.rowOffsets[size_t(y)])));
    check(offsetDiff <= int(allowed), "row offsets differ from the original");
  }
  return ok;
}
} // namespace

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
  const bool heatOk = worst < 1e-4f && std::fabs(impls[2]->m_total - impls[0]->m_total) < 1e-2f && impls[0]->m_total > 5999.0f;
  const bool ok = CheckRayCaster() && heatOk;
  std::printf(ok ? "OK\n" : "MISMATCH\n");
  return ok ? 0 : 1;
}
