// Shared by the radix sort shaders: records of `stride` 32-bit words, sorted by the word at
// `keyWord`, read as uint, int or float (keyMode bits 0-1) and ascending or descending (bit 2).
// With keyMode bit 3 the records to sort are min(n, countWords[countWord]): a count that only
// the GPU has (the size of a vector kernels appended to), n then being the buffer's capacity.
layout(push_constant) uniform Args { uint n; uint shift; uint tiles; uint stride; uint keyWord; uint keyMode; uint countWord; };

uint RecordCount()
{
  return (keyMode & 8u) != 0u ? min(n, countWords[countWord]) : n;
}

// Maps a key to a uint whose unsigned order is the requested order of the keys.
uint SortableKey(uint k)
{
  const uint type = keyMode & 3u;
  if (type == 1u)
    k ^= 0x80000000u;  // int: the sign bit decides first
  else if (type == 2u)
  {
    if (k == 0x80000000u)
      k = 0u;  // -0.0f sorts with +0.0f, as std::sort's comparator sees them equal
    k = (k & 0x80000000u) != 0u ? ~k : (k | 0x80000000u);  // negative floats in reverse
  }
  return (keyMode & 4u) != 0u ? ~k : k;
}
