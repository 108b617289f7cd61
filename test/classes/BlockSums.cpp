#include "BlockSums.h"

// A helper of the source file, as users write them: the CPU class gets a copy of it.
static float Offset(float first) { return first; }

void BlockSums::Scan(uint numElements, const float* in, float* out)
{
  kernelBE1D_Scan<64>(numElements / 64, in, out);
}

template <uint bsize>
void BlockSums::kernelBE1D_Scan(uint blockNum, const float* in, float* out)
{
  for (uint blockId = 0; blockId < blockNum; blockId++)
  {
    float blockData[bsize];  // the block's shared memory
    for (uint localId = 0; localId < bsize; localId++) [[parallel]]
    {
      blockData[localId] = in[blockId * bsize + localId];
    }
    for (uint localId = 1; localId < bsize; localId++)  // one thread: the scan
      blockData[localId] += blockData[localId - 1];
    const float first = blockData[0];
    for (uint localId = 0; localId < bsize; localId++) [[parallel]]
    {
      out[blockId * bsize + localId] = blockData[localId] + Offset(first);
    }
  }
}
