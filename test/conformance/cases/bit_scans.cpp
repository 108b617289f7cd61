#include "bit_scans.h"

// The index of the highest set bit, -1 for none.
static int HighestBit(uint32_t x) { return x == 0u ? -1 : 31 - __builtin_clz(x); }

void BitScans::Scan(int n, const uint32_t* words, int4* counts) { kernel1D_Scan(n, words, counts); }

void BitScans::kernel1D_Scan(int n, const uint32_t* words, int4* counts)
{
  for (int i = 0; i < n; i++)
  {
    const uint32_t w = words[i];
    const int leading = w == 0u ? 32 : __builtin_clz(w);
    const int trailing = w == 0u ? 32 : __builtin_ctz(w);
    const int ones = __builtin_popcount(w);
    const uint32_t next = i + 1 < n ? words[i + 1] : 0u;
    const int shared = HighestBit(w ^ next);  // -1 where the two words are equal
    counts[i] = int4(leading, trailing, ones, 100 * shared + HighestBit(w));
  }
}
