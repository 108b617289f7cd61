// A set that iterates in the order its elements were first inserted. The printer collects AST
// nodes (members, images, virtual calls) in the order it meets them; iterating by pointer value
// instead would order generated code by where the AST happens to sit in memory.
#pragma once
#include <algorithm>
#include <set>
#include <utility>
#include <vector>

namespace crossrt::engine {

template <class T>
class OrderedSet {
public:
  using const_iterator = typename std::vector<T>::const_iterator;
  std::pair<const_iterator, bool> insert(const T& x) {
    if (!m_seen.insert(x).second) return {std::find(m_order.begin(), m_order.end(), x), false};
    m_order.push_back(x);
    return {m_order.end() - 1, true};
  }
  size_t count(const T& x) const { return m_seen.count(x); }
  size_t erase(const T& x) {
    if (!m_seen.erase(x)) return 0;
    m_order.erase(std::find(m_order.begin(), m_order.end(), x));
    return 1;
  }
  bool empty() const { return m_order.empty(); }
  size_t size() const { return m_order.size(); }
  const_iterator begin() const { return m_order.begin(); }
  const_iterator end() const { return m_order.end(); }
  void clear() { m_order.clear(); m_seen.clear(); }

private:
  std::vector<T> m_order;
  std::set<T> m_seen;
};

}  // namespace crossrt::engine
