// Runs VectorOps as written and FastVectorOps (generated class + hand-written kernel); prints
// both results and whether the hand-written kernel ran.
#include "FastVectorOps.h"

#include "CommandLine.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv)
{
  crossrt::CommandLine app("custom_kernel",
                           "Runs VectorOps as written and FastVectorOps (the generated class with a hand-written kernel),\n"
                           "prints both results and whether the hand-written kernel ran.");
  if (const int status = crossrt::ParseCommandLine(app, argc, argv); status >= 0) return status;
  const int n = 10001;
  std::vector<float> expected(n), actual(n);
  for (int i = 0; i < n; ++i) expected[i] = actual[i] = 0.001f * float(i);
  VectorOps original;
  original.Process(n, expected.data());
  FastVectorOps fast(crossrt::VulkanContext::CreateDefault());
  fast.Process(n, actual.data());
  float worst = 0.0f;
  for (int i = 0; i < n; ++i) worst = std::max(worst, std::fabs(expected[i] - actual[i]));
  std::printf("data[1000]: original %.4f, FastVectorOps %.4f; largest difference %.3g\n", expected[1000], actual[1000], worst);
  std::printf("hand-written kernel dispatches: %d\n", fast.handWrittenDispatches);
  const bool ok = worst < 1e-5f && fast.handWrittenDispatches == 1;
  std::printf(ok ? "OK\n" : "MISMATCH\n");
  return ok ? 0 : 1;
}
