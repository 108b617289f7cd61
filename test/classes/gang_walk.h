// A user's class that walks a sorted table together with its gang (Gang.h), written as a new user
// would: in a file not named after the class, a static helper in the .cpp, a sum set up before the
// kernel and a mean written after it. Each query counts the keys at or below it. The gang moves past
// whole blocks of keys together while any of its queries lies beyond them (one load of a block's
// last key for all lanes on ISPC); each query then steps back alone to its own block, and the gang
// counts in each query's block in turn, its lanes sharing out the keys (LaneBits, LaneValue,
// LaneIndex), so a count never depends on the queries beside it (test/equivalence/test_gang.cpp). A NaN
// query gets kNoCount and leaves its gang's walk; where no lane has left, the results are written in
// a branch that crossrt::AllLanesOn() guards (ISPC: unmasked). CountQuarters counts the keys that
// start the table's quarters at or below each query, a quad of lanes per query where every lane of a
// gang of four or more is on (LaneOfQuad, FromLane), and as Count counts a block elsewhere (LaneOf).
#pragma once
#include "Gang.h"
#include "LiteMath.h"

#include <cstdint>
#include <vector>

class KeyCounter
{
public:
  explicit KeyCounter(std::vector<float> sortedKeys) : m_keys(std::move(sortedKeys))
  {
    const size_t quarter = m_keys.size() / 4;
    if (!m_keys.empty())
      m_quarters = LiteMath::float4(m_keys[0], m_keys[quarter], m_keys[2 * quarter], m_keys[3 * quarter]);
  }
  virtual ~KeyCounter() = default;

  // counts[i] = the keys <= queries[i] (kNoCount for a NaN); m_total their sum, m_mean their mean.
  virtual void Count(int n, [[crossrt::size("n")]] const float* queries, [[crossrt::size("n")]] uint32_t* counts);
  // counts[i] = the keys of m_quarters <= queries[i] (kNoCount for a NaN).
  virtual void CountQuarters(int n, [[crossrt::size("n")]] const float* queries, [[crossrt::size("n")]] uint32_t* counts);
  virtual void CommitDeviceData() {}

  static constexpr int kBlock = 8;
  static constexpr uint32_t kNoCount = 0xFFFFFFFFu;  // a NaN query's count
  std::vector<float> m_keys;  // ascending
  LiteMath::float4 m_quarters = LiteMath::float4(0.0f);  // the first key of each quarter of m_keys
  uint32_t m_total = 0;
  float m_mean = 0.0f;

protected:
  void kernel1D_Count(int n, const float* queries, uint32_t* counts);
  void kernel1D_CountQuarters(int n, const float* queries, uint32_t* counts);
};
