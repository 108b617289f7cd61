// Code generation: renders the templates in templates/ from a ClassModel.
#pragma once
#include "Model.h"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace crossrt::engine {

struct GenerateOptions {
  std::string templateDir;
  std::string headerName;     // the user header's file name, for comments
  std::string headerInclude;  // how generated code includes it
  std::function<std::string(const std::string&)> includeSpelling;  // the same, for any header
};

struct ShaderSource {
  std::string name;  // kernel name, or kernel + "_Reduce", "_RayQuery", ...; a callable shader's name
  std::string glsl;
  std::string stage = "comp";  // the file's extension, which names the stage: comp, rgen, rcall, rint, rchit or rmiss
};

std::vector<ShaderSource> GenerateShaders(const ClassModel& model, const GenerateOptions& options);
// Host C++ of the Vulkan class (vulkan = true) or of the CPU class.
std::map<std::string, std::string> GenerateHost(const ClassModel& model, const GenerateOptions& options, bool vulkan);
// The ISPC backend (IspcCode.cpp): <Class>_ISPC_kernels.ispc.
std::string GenerateIspcKernels(const ClassModel& model, const GenerateOptions& options);
// How the ISPC class hands out a loop's threads to the cores: chunks of this many iterations of a
// 1D loop; a tiled 2D loop four rows at a time (a foreach_tiled tile is up to 4 rows high). Other 2D
// and 3D nests hand out rows and slices one by one.
constexpr int kIspcChunk1D = 4096;
constexpr int kIspcTileRows = 4;
// float, int, uint, bool or double: passed by value between C++ and ISPC.
bool IsIspcScalar(const std::string& glslType);
// The C++ type the ISPC header gives a parameter of this GLSL type (int32_t, ispc::float4, ...).
std::string IspcCppType(const std::string& glslType);
// The per-target symbols of ISPC export function `symbol`, as IspcPick lists them.
std::string IspcTargetFunctions(const std::string& symbol);

}  // namespace crossrt::engine
