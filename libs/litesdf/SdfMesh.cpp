// SdfMesh (SdfMesh.h): pseudo-normals, the closest point over the BVH, the winding number exactly
// and over the BVH's clusters.
#include "SdfMesh.h"

#include "SAHBuilder.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

namespace litesdf {

namespace {

using LiteMath::cross;
using LiteMath::dot;
using LiteMath::float4;

float3 SafeNormalize(float3 v) {
  const float len = LiteMath::length(v);
  return len > 0.0f ? v / len : float3(0.0f, 0.0f, 0.0f);
}

// Where on triangle abc the point closest to p lies (Ericson, Real-Time Collision Detection 5.1.5).
enum class Feature { VertexA, VertexB, VertexC, EdgeAB, EdgeBC, EdgeCA, Face };
struct Closest {
  float3 point;
  Feature feature;
};

Closest ClosestOnTriangle(float3 p, float3 a, float3 b, float3 c) {
  const float3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0f && d2 <= 0.0f) return {a, Feature::VertexA};
  const float3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0f && d4 <= d3) return {b, Feature::VertexB};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return {a + (d1 / (d1 - d3)) * ab, Feature::EdgeAB};
  const float3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0f && d5 <= d6) return {c, Feature::VertexC};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return {a + (d2 / (d2 - d6)) * ac, Feature::EdgeCA};
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
    return {b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b), Feature::EdgeBC};
  const float denom = 1.0f / (va + vb + vc);
  return {a + ab * (vb * denom) + ac * (vc * denom), Feature::Face};
}

// The signed solid angle of triangle abc seen from p, positive when p is on its back (inside):
// Van Oosterom and Strackee, tan(omega / 2) = det(a b c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|).
double SolidAngle(float3 p, float3 va, float3 vb, float3 vc) {
  const float3 a = va - p, b = vb - p, c = vc - p;
  const double la = LiteMath::length(a), lb = LiteMath::length(b), lc = LiteMath::length(c);
  const double det = dot(a, cross(b, c));
  const double div = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
  if (det == 0.0) return 0.0;  // p in the triangle's plane: no solid angle (atan2(0, -x) would say 2 pi)
  return 2.0 * std::atan2(det, div);
}

// A cluster counts as one dipole once p is further from its centre than this many radii. Barill
// et al. use 2: the dipole's error then stays well under the 1/2 the sign is read against.
constexpr float kFarRadii = 2.0f;

float BoxDistanceSquared(float3 p, float3 boxMin, float3 boxMax) {
  const float3 d = LiteMath::max(LiteMath::max(boxMin - p, p - boxMax), float3(0.0f, 0.0f, 0.0f));
  return dot(d, d);
}

}  // namespace

std::vector<float3> FitIntoCube(const std::vector<float>& positions, float halfExtent) {
  for (size_t k = 0; k < positions.size(); ++k)
    if (!std::isfinite(positions[k]))
      throw std::invalid_argument("FitIntoCube: vertex " + std::to_string(k / 3) + " is not finite (NaN or infinite)");
  std::vector<float3> vertices(positions.size() / 3);
  for (size_t v = 0; v < vertices.size(); ++v) vertices[v] = float3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
  if (vertices.empty()) return vertices;
  float3 lo = vertices[0], hi = vertices[0];
  for (const float3& p : vertices) {
    lo = LiteMath::min(lo, p);
    hi = LiteMath::max(hi, p);
  }
  const float3 center = 0.5f * (lo + hi);
  const float extent = std::max(hi.x - lo.x, std::max(hi.y - lo.y, hi.z - lo.z));
  const float scale = extent > 0.0f ? 2.0f * halfExtent / extent : 1.0f;
  for (float3& p : vertices) p = (p - center) * scale;
  return vertices;
}

SdfMesh::SdfMesh(std::vector<float3> vertices, std::vector<uint32_t> indices, SdfSign sign)
    : m_vertices(std::move(vertices)), m_indices(std::move(indices)) {
  if (m_indices.empty() || m_indices.size() % 3 != 0) throw std::invalid_argument("a mesh needs triangles: three indices each");
  for (uint32_t i : m_indices)
    if (i >= m_vertices.size()) throw std::invalid_argument("a triangle index is out of the vertices' range");
  for (size_t t = 0; t < m_indices.size(); ++t) {
    const float3 v = m_vertices[m_indices[t]];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw std::invalid_argument("vertex " + std::to_string(m_indices[t]) + " of triangle " + std::to_string(t / 3) + " is not finite (NaN or infinite)");
  }
  const size_t triangles = m_indices.size() / 3;
  m_faceNormals.resize(triangles);
  m_vertexNormals.assign(m_vertices.size(), float3(0.0f, 0.0f, 0.0f));
  m_edgeNormals.assign(3 * triangles, float3(0.0f, 0.0f, 0.0f));
  struct EdgeFaces {
    float3 normalSum;
    uint32_t faces = 0;
  };
  std::map<std::pair<uint32_t, uint32_t>, EdgeFaces> edges;  // undirected edge -> its faces
  std::vector<LiteMath::Box4f> boxes(triangles);
  m_boxMin = m_boxMax = m_vertices[m_indices[0]];
  for (size_t t = 0; t < triangles; ++t) {
    const uint32_t* v = &m_indices[3 * t];
    const float3 p[3] = {m_vertices[v[0]], m_vertices[v[1]], m_vertices[v[2]]};
    const float3 n = SafeNormalize(cross(p[1] - p[0], p[2] - p[0]));
    m_faceNormals[t] = n;
    for (int k = 0; k < 3; ++k) {
      // The vertex's share: the face's normal weighted by the face's angle at the vertex.
      const float3 e0 = SafeNormalize(p[(k + 1) % 3] - p[k]), e1 = SafeNormalize(p[(k + 2) % 3] - p[k]);
      m_vertexNormals[v[k]] += std::acos(LiteMath::clamp(dot(e0, e1), -1.0f, 1.0f)) * n;
      const uint32_t a = v[k], b = v[(k + 1) % 3];
      EdgeFaces& edge = edges[{std::min(a, b), std::max(a, b)}];
      edge.normalSum += n;
      ++edge.faces;
      boxes[t].include(float4(p[k].x, p[k].y, p[k].z, 0.0f));
      m_boxMin = LiteMath::min(m_boxMin, p[k]);
      m_boxMax = LiteMath::max(m_boxMax, p[k]);
    }
  }
  for (size_t t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m_indices[3 * t + k], b = m_indices[3 * t + (k + 1) % 3];
      m_edgeNormals[3 * t + k] = edges[{std::min(a, b), std::max(a, b)}].normalSum;
    }
  for (const auto& edge : edges) m_badEdges += edge.second.faces != 2;
  m_bvh = BuildBinnedSAH(boxes.data(), int(triangles), 4);
  m_sign = sign != SdfSign::Auto ? sign : m_badEdges == 0 ? SdfSign::PseudoNormal : SdfSign::WindingNumber;
  if (m_sign != SdfSign::WindingNumber) return;

  // The clusters, children before parents: a node's index is always below its children's.
  m_clusters.resize(m_bvh.nodes.size());
  std::vector<float> areas(m_bvh.nodes.size());
  for (size_t i = m_bvh.nodes.size(); i-- > 0;) {
    const BVHNode& node = m_bvh.nodes[i];
    Cluster& cluster = m_clusters[i];
    if (node.left & kLeafFlag) {
      const uint32_t first = node.left & ~kLeafFlag;
      float3 weighted(0.0f, 0.0f, 0.0f), centroids(0.0f, 0.0f, 0.0f), areaNormal(0.0f, 0.0f, 0.0f);
      float area = 0.0f;
      for (uint32_t j = first; j < first + node.right; ++j) {
        const uint32_t* v = &m_indices[3 * m_bvh.primIndices[j]];
        const float3 a = m_vertices[v[0]], b = m_vertices[v[1]], c = m_vertices[v[2]];
        const float3 n = 0.5f * cross(b - a, c - a);
        const float3 centroid = (a + b + c) / 3.0f;
        weighted += LiteMath::length(n) * centroid;
        centroids += centroid;
        areaNormal += n;
        area += LiteMath::length(n);
      }
      cluster.center = area > 0.0f ? weighted / area : centroids / float(std::max(node.right, 1u));
      cluster.radius = 0.0f;
      for (uint32_t j = first; j < first + node.right; ++j)
        for (int k = 0; k < 3; ++k)
          cluster.radius = std::max(cluster.radius, LiteMath::length(m_vertices[m_indices[3 * m_bvh.primIndices[j] + k]] - cluster.center));
      cluster.areaNormal = areaNormal;
      areas[i] = area;
      continue;
    }
    if (node.left <= i || node.right <= i) throw std::logic_error("SdfMesh: a BVH child before its parent");
    const Cluster &l = m_clusters[node.left], &r = m_clusters[node.right];
    const float area = areas[node.left] + areas[node.right];
    cluster.center = area > 0.0f ? (areas[node.left] * l.center + areas[node.right] * r.center) / area : 0.5f * (l.center + r.center);
    cluster.radius = std::max(LiteMath::length(l.center - cluster.center) + l.radius, LiteMath::length(r.center - cluster.center) + r.radius);
    cluster.areaNormal = l.areaNormal + r.areaNormal;
    areas[i] = area;
  }
}

float SdfMesh::NearestSquared(float3 p, float3& bestPoint, float3& bestNormal) const {
  float best = INFINITY;
  bestPoint = bestNormal = float3(0.0f, 0.0f, 0.0f);
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BVHNode& node = m_bvh.nodes[stack[--top]];
    if (BoxDistanceSquared(p, node.boxMin, node.boxMax) >= best) continue;
    if (node.left & kLeafFlag) {
      const uint32_t first = node.left & ~kLeafFlag;
      for (uint32_t i = first; i < first + node.right; ++i) {
        const uint32_t t = m_bvh.primIndices[i];
        const uint32_t* v = &m_indices[3 * t];
        const Closest c = ClosestOnTriangle(p, m_vertices[v[0]], m_vertices[v[1]], m_vertices[v[2]]);
        const float3 d = p - c.point;
        const float d2 = dot(d, d);
        if (d2 >= best) continue;
        best = d2;
        bestPoint = c.point;
        switch (c.feature) {
          case Feature::VertexA: bestNormal = m_vertexNormals[v[0]]; break;
          case Feature::VertexB: bestNormal = m_vertexNormals[v[1]]; break;
          case Feature::VertexC: bestNormal = m_vertexNormals[v[2]]; break;
          case Feature::EdgeAB: bestNormal = m_edgeNormals[3 * t + 0]; break;
          case Feature::EdgeBC: bestNormal = m_edgeNormals[3 * t + 1]; break;
          case Feature::EdgeCA: bestNormal = m_edgeNormals[3 * t + 2]; break;
          case Feature::Face: bestNormal = m_faceNormals[t]; break;
        }
      }
      continue;
    }
    // The nearer child last, so that it is visited first.
    const BVHNode& l = m_bvh.nodes[node.left];
    const BVHNode& r = m_bvh.nodes[node.right];
    const bool leftNearer = BoxDistanceSquared(p, l.boxMin, l.boxMax) < BoxDistanceSquared(p, r.boxMin, r.boxMax);
    if (top + 2 > 64) throw std::runtime_error("SdfMesh: BVH deeper than 64 levels");
    stack[top++] = leftNearer ? node.right : node.left;
    stack[top++] = leftNearer ? node.left : node.right;
  }
  return best;
}

float SdfMesh::UnsignedDistance(float3 p) const {
  float3 nearest, pseudoNormal;
  return std::sqrt(NearestSquared(p, nearest, pseudoNormal));
}

float SdfMesh::Distance(float3 p) const {
  float3 nearest, pseudoNormal;
  const float distance = std::sqrt(NearestSquared(p, nearest, pseudoNormal));
  const bool inside = m_sign == SdfSign::WindingNumber ? FastWindingNumber(p) >= 0.5f : dot(p - nearest, pseudoNormal) < 0.0f;
  return inside ? -distance : distance;
}

float SdfMesh::WindingNumber(float3 p) const {
  double total = 0.0;
  for (size_t t = 0; t < m_indices.size() / 3; ++t)
    total += SolidAngle(p, m_vertices[m_indices[3 * t]], m_vertices[m_indices[3 * t + 1]], m_vertices[m_indices[3 * t + 2]]);
  return float(total / (4.0 * double(LiteMath::M_PI)));
}

float SdfMesh::FastWindingNumber(float3 p) const {
  if (m_clusters.empty()) return WindingNumber(p);  // a pseudo-normal mesh has no clusters
  double total = 0.0;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t i = stack[--top];
    const Cluster& cluster = m_clusters[i];
    const float3 toCenter = cluster.center - p;
    const float d2 = dot(toCenter, toCenter);
    if (d2 > kFarRadii * kFarRadii * cluster.radius * cluster.radius) {
      // The dipole: the solid angle of a small patch of area vector A at distance r is A.r / |r|^3.
      total += double(dot(cluster.areaNormal, toCenter)) / (double(d2) * std::sqrt(double(d2)));
      continue;
    }
    const BVHNode& node = m_bvh.nodes[i];
    if (node.left & kLeafFlag) {
      const uint32_t first = node.left & ~kLeafFlag;
      for (uint32_t j = first; j < first + node.right; ++j) {
        const uint32_t* v = &m_indices[3 * m_bvh.primIndices[j]];
        total += SolidAngle(p, m_vertices[v[0]], m_vertices[v[1]], m_vertices[v[2]]);
      }
      continue;
    }
    if (top + 2 > 64) throw std::runtime_error("SdfMesh: BVH deeper than 64 levels");
    stack[top++] = node.left;
    stack[top++] = node.right;
  }
  return float(total / (4.0 * double(LiteMath::M_PI)));
}

}  // namespace litesdf
