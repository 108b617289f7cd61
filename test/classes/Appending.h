// Appends and indirect dispatch: kernels push_back to member vectors, and later kernels loop to
// those vectors' sizes. On the GPU the appends go through an atomic counter and the later kernels
// are dispatched indirectly, with no host round trip (test/equivalence/test_append.cpp). The class
// sits in a nested namespace, as users' classes do: the generated classes join it.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

namespace demo::appends
{
// A record one kernel appends and the next one reads.
struct Candidate
{
  uint32_t index;
  float value;
};

class Appending
{
public:
  // Room for `capacity` appends per vector: the GPU keeps at most the capacity.
  explicit Appending(int capacity)
  {
    m_positive.reserve(capacity);
    m_large.reserve(capacity);
    m_negative.reserve(2 * capacity);
    m_small.reserve(capacity);
    m_tagged.reserve(capacity);
  }
  virtual ~Appending() = default;

  // Two stages: m_positive gets the indices of the positive values, m_large gets {index, 2 * value}
  // of those above `threshold`, and out[index] = 2 * value for each of those. The order of the
  // appended elements is unspecified (threads append as they arrive).
  virtual void Select(int n, float threshold, [[crossrt::size("n")]] const float* values,
                      [[crossrt::size("n")]] float* out);
  // Select, then each appended vector sorted in the same call: m_positive descending, m_large by
  // value. ranks[index] = the position of index in the sorted m_large (unchanged elsewhere).
  virtual void SelectSorted(int n, float threshold, [[crossrt::size("n")]] const float* values,
                            [[crossrt::size("n")]] float* ranks);
  // Appends the indices of the negative values to m_negative without clearing it first.
  virtual void Collect(int n, [[crossrt::size("n")]] const float* values);
  // Appends made away from the kernel's loop: m_small gets the indices of the values with
  // |value| < 0.1 through two helpers, m_tagged gets {index, value} of those above 0.9 from a
  // kernel_ function whose loop is here, in the control function.
  virtual void Classify(int n, [[crossrt::size("n")]] const float* values);
  // room[i] = the elements m_negative has room for before it must grow, for every i: kernels read
  // capacity() and size() as the control function found them.
  virtual void Room(int n, [[crossrt::size("n")]] uint32_t* room);
  virtual void CommitDeviceData() {}

  std::vector<uint32_t> m_positive;
  std::vector<Candidate> m_large;
  std::vector<uint32_t> m_negative;
  std::vector<uint32_t> m_small;
  std::vector<Candidate> m_tagged;

protected:
  void kernel1D_FindPositive(int n, const float* values);
  void kernel1D_FindLarge(float threshold, const float* values);  // over m_positive
  void kernel1D_Write(float* out);                                 // over m_large
  void kernel1D_Rank(float* ranks);                                // over m_large
  void kernel1D_FindNegative(int n, const float* values);
  void kernel1D_FindSmall(int n, const float* values);
  virtual void kernel_Tag(int tid, const float* values);
  void kernel1D_Room(int n, uint32_t* room);

  // 1 if it appended i. The default argument, the overload and the helper it calls are part of
  // the test: the CPU backend copies this one, and the copy must still call the other overload.
  uint32_t NoteSmall(uint32_t i, float value, float limit = 0.1f);
  static bool NoteSmall(float value, float limit) { return std::abs(value) < limit; }
  void Append(uint32_t i) { m_small.push_back(i); }
};
}  // namespace demo::appends
