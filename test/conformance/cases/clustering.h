// Lloyd's k-means on 2D points, as a user writes it: a kernel assigns each point to its nearest
// centroid and sums each cluster's points; between kernel calls the host clears the sums, moves the
// centroids to the means and stops once no point changed cluster (issue 52: member vectors read and
// written on the host between kernel calls). The file is not named after the class.
#pragma once
#include "LiteMath.h"

#include <vector>

using namespace LiteMath;

class KMeans
{
public:
  // a_points points on integer coordinates in four blobs.
  KMeans(int a_points = 600, int a_clusters = 4);
  virtual ~KMeans() = default;
  virtual void CommitDeviceData() {}

  // At most a_maxIterations rounds of assign-and-update; stops when no label changed.
  virtual void Fit(int a_maxIterations);

  int Iterations() const { return m_iterations; }
  const std::vector<float2>& Centroids() const { return m_centroids; }
  const std::vector<int>& Labels() const { return m_labels; }
  const std::vector<int>& Counts() const { return m_counts; }

protected:
  void kernel1D_Assign(int a_count);

  int m_clusters;
  std::vector<float2> m_points, m_centroids;
  std::vector<float> m_sums;  // x and y of each cluster's points
  std::vector<int> m_counts, m_labels;
  int m_changed = 0;
  int m_iterations = 0;
};
