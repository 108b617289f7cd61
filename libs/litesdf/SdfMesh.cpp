// SdfMesh (SdfMesh.h): pseudo-normals, the closest point over the BVH, the winding number.
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

float BoxDistanceSquared(float3 p, float3 boxMin, float3 boxMax) {
  const float3 d = LiteMath::max(LiteMath::max(boxMin - p, p - boxMax), float3(0.0f, 0.0f, 0.0f));
  return dot(d, d);
}

}  // namespace

std::vector<float3> FitIntoCube(const std::vector<float>& positions, float halfExtent) {
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

SdfMesh::SdfMesh(std::vector<float3> vertices, std::vector<uint32_t> indices)
    : m_vertices(std::move(vertices)), m_indices(std::move(indices)) {
  if (m_indices.empty() || m_indices.size() % 3 != 0) throw std::invalid_argument("a mesh needs triangles: three indices each");
  for (uint32_t i : m_indices)
    if (i >= m_vertices.size()) throw std::invalid_argument("a triangle index is out of the vertices' range");
  const size_t triangles = m_indices.size() / 3;
  m_faceNormals.resize(triangles);
  m_vertexNormals.assign(m_vertices.size(), float3(0.0f, 0.0f, 0.0f));
  m_edgeNormals.assign(3 * triangles, float3(0.0f, 0.0f, 0.0f));
  std::map<std::pair<uint32_t, uint32_t>, float3> edgeSums;  // undirected edge -> sum of its faces' normals
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
      edgeSums[{std::min(a, b), std::max(a, b)}] += n;
      boxes[t].include(float4(p[k].x, p[k].y, p[k].z, 0.0f));
      m_boxMin = LiteMath::min(m_boxMin, p[k]);
      m_boxMax = LiteMath::max(m_boxMax, p[k]);
    }
  }
  for (size_t t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m_indices[3 * t + k], b = m_indices[3 * t + (k + 1) % 3];
      m_edgeNormals[3 * t + k] = edgeSums[{std::min(a, b), std::max(a, b)}];
    }
  m_bvh = BuildBinnedSAH(boxes.data(), int(triangles), 4);
}

float SdfMesh::Distance(float3 p) const {
  float best = INFINITY;
  float3 bestPoint(0.0f, 0.0f, 0.0f), bestNormal(0.0f, 0.0f, 0.0f);
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
  const float distance = std::sqrt(best);
  return dot(p - bestPoint, bestNormal) < 0.0f ? -distance : distance;
}

float SdfMesh::WindingNumber(float3 p) const {
  // Van Oosterom and Strackee: tan(omega / 2) = det(a b c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|).
  double total = 0.0;
  for (size_t t = 0; t < m_indices.size() / 3; ++t) {
    const float3 a = m_vertices[m_indices[3 * t]] - p, b = m_vertices[m_indices[3 * t + 1]] - p, c = m_vertices[m_indices[3 * t + 2]] - p;
    const double la = LiteMath::length(a), lb = LiteMath::length(b), lc = LiteMath::length(c);
    const double det = dot(a, cross(b, c));
    const double div = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    if (det == 0.0) continue;  // p in the triangle's plane: no solid angle (atan2(0, -x) would say 2 pi)
    total += 2.0 * std::atan2(det, div);
  }
  return float(total / (4.0 * double(LiteMath::M_PI)));
}

}  // namespace litesdf
