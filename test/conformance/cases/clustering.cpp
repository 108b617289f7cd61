#include "clustering.h"

#include <cstdint>

namespace {
// A point of blob (i % 4): integer coordinates, so that sums of them are exact in any order.
float2 BlobPoint(int i)
{
  static const float2 centers[4] = {float2(10, 10), float2(70, 15), float2(40, 60), float2(85, 80)};
  uint32_t h = uint32_t(i) * 2654435761u;
  h ^= h >> 15;
  const float dx = float(int(h % 13u) - 6), dy = float(int((h >> 8) % 13u) - 6);
  const float2 c = centers[i % 4];
  return float2(c.x + dx, c.y + dy);
}
}  // namespace

KMeans::KMeans(int a_points, int a_clusters) : m_clusters(a_clusters)
{
  for (int i = 0; i < a_points; ++i)
    m_points.push_back(BlobPoint(i * 7 + 3));
  // The first centroids: off the blobs, so that it takes a few rounds.
  static const float2 starts[4] = {float2(30, 30), float2(50, 30), float2(45, 45), float2(60, 55)};
  for (int k = 0; k < a_clusters; ++k)
    m_centroids.push_back(starts[k % 4] + float2(0.0f, float(k / 4)));
  m_sums.resize(2 * size_t(a_clusters));
  m_counts.resize(size_t(a_clusters));
  m_labels.assign(size_t(a_points), -1);
}

void KMeans::kernel1D_Assign(int a_count)
{
  for (int i = 0; i < a_count; ++i)
  {
    const float2 p = m_points[i];
    int best = 0;
    float bestDistance = 1e30f;
    for (int k = 0; k < m_clusters; ++k)
    {
      const float2 d = p - m_centroids[k];
      const float distance = d.x * d.x + d.y * d.y;
      if (distance < bestDistance)
      {
        bestDistance = distance;
        best = k;
      }
    }
    if (m_labels[i] != best)
    {
      m_labels[i] = best;
      m_changed += 1;
    }
    InterlockedAdd(m_counts[best], 1);
    ReduceAdd<float, int>(m_sums, 2 * best, p.x);
    ReduceAdd<float, int>(m_sums, 2 * best + 1, p.y);
  }
}

void KMeans::Fit(int a_maxIterations)
{
  m_iterations = 0;
  for (int iteration = 0; iteration < a_maxIterations; ++iteration)
  {
    for (int& count : m_counts)
      count = 0;
    ReduceAddInit(m_sums, m_sums.size());
    m_changed = 0;
    kernel1D_Assign(int(m_points.size()));
    ReduceAddComplete(m_sums);
    m_iterations++;
    // The centroids move to their clusters' means; an empty cluster stays where it is.
    for (int k = 0; k < m_clusters; ++k)
      if (m_counts[k] > 0)
        m_centroids[k] = float2(m_sums[2 * k], m_sums[2 * k + 1]) / float(m_counts[k]);
    if (m_changed == 0)
      break;
  }
}
