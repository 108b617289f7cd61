// What the code generators share: rendering a template of templates/ from mustache data, the data
// every generated file gets (Common), a kernel's shader variants and its dispatch sizes.
#pragma once
#include "generate/CodeGen.h"

#include <kainjow/mustache.hpp>

#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {

using Data = kainjow::mustache::data;

Data List();

// The shaders of a kernel, most specific first (the order the host tries them in): the variants for
// ray tracing hardware and for arrays of textures on the GPU's samplers, and the one every device runs.
struct KernelVariant {
  std::string suffix;  // "_Callables", "_Intersections" (either + "_Textures"), "_RayQuery_Textures", "_RayQuery", "_Textures" or ""
  bool rayQuery = false, textures = false, callables = false, leaves = false;
  // "Start" or "Finish": the one-thread shader of the statements before or after the loop nest,
  // with the bindings of the variant every device runs.
  std::string phase;
  // A phase of a kernel with a ray query variant, whose statements do not trace: it binds the class's
  // own vectors and functions only, as the ray query variant does, so that it runs however the scene
  // is held (the translated traversal's buffers are not uploaded while the hardware traces).
  bool ownVectors = false;
  bool RayGeneration() const { return callables || leaves; }  // a ray generation shader, not a compute shader
};

// The specialization constants from kClassConstantIdBase: one per class of each vector of objects
// called through virtual functions (ClassConstantCount of them), then the CRT_SPECIALIZE members
// kernels read, in member order (constant id kClassConstantIdBase + ClassConstantCount + index).
unsigned ClassConstantCount(const ClassModel& model);
std::vector<const Member*> SpecializedMembers(const ClassModel& model);

// The one-thread shaders of a kernel's statements before and after its loop nest (loop_start, loop_end).
std::vector<KernelVariant> Phases(const Kernel& k);

// Why a kernel with virtual calls at level 3 has no callables variant ("" when it has one).
std::string WhyNoCallables(const Kernel& k);

bool RunsCallables(const Kernel& k);

bool RunsLeafShaders(const Kernel& k);

// Why a kernel whose composed traversal calls a virtual function per leaf keeps that loop in software.
std::string WhyNoLeafShaders(const Kernel& k);

// The vectors whose leaves a kernel's traces find, once each, in the traces' order: one
// acceleration structure each.
std::vector<const LeafTraversal*> LeafScenes(const Kernel& k);

// "a, b and c"
std::string Listed(const std::vector<std::string>& items);

// The vectors whose leaves a kernel's traces find: "m_scene->m_shapes and m_scene->m_lights".
std::string LeafDisplays(const Kernel& k);

// The shaders of ray tracing pipelines besides the kernels' that some kernel's ray generation
// variant executes: callables, then intersection, closest-hit and miss shaders, in the model's order.
std::vector<const StageShader*> ExecutedStageShaders(const ClassModel& model);

std::vector<KernelVariant> Variants(const Kernel& k);

std::string Render(const std::string& templatePath, const Data& data);

// Indents every line but the first (which the template already indents).
std::string IndentTail(const std::string& text, const std::string& pad);

// The specialization constant that switches the fences of crossrt atomics (crt_fenceAtomics). The
// runtime names it crossrt::kFenceAtomicsConstantId; generated host code static_asserts they agree.
inline constexpr const char* kFenceAtomicsConstantId = "1700";

// The first specialization constant of virtual calls specialised to the scene: constant
// kClassConstantIdBase + i says whether the objects hold class i (crossrt::kClassConstantIdBase).
inline constexpr unsigned kClassConstantIdBase = 1800;

const char* Axis(unsigned a);

const char* GlAxis(unsigned a);

// What the Vulkan class dispatches: the kernels, then the megakernels of thread loops.
std::vector<const Kernel*> VulkanKernels(const ClassModel& model);

// Workgroup shape by dimension count: 256 threads each, so reductions see the same group size.
struct GroupShape { unsigned x, y, z; };

GroupShape Shape(const Kernel& k);

std::string Combine(ReduceOp op, const std::string& a, const std::string& b);

std::string GroupCountExpr(const Kernel& k);

std::string DispatchExpr(const Kernel& k);

// The launch of a kernel's ray generation variant: a thread per kernel thread. 1D counts go in
// rows of 65536, within every device's launch width (maxComputeWorkGroupCount[0] x group size).
std::string LaunchSize(const Kernel& k);

// The C++ type of a reduction's value (of one element, where an array's elements are reduced).
std::string ReductionCppType(const ClassModel& model, const Reduction& r);
// How many elements of an array a reduction reduces (a member's coefs[k] += x, a local's bins[b] += x), or "" for a whole value.
std::string ReductionElements(const Reduction& r);

Data Common(const ClassModel& model, const GenerateOptions& opt);
// What the CPU and ISPC classes' kernel functions share: name, source, parameters, and the
// statements before and after the loop nest that the host runs.
Data CpuKernelData(const Kernel& k);
// The first parameter of an _ISPC kernel's two ways (crossrt::LaneChoice's run, which each tells its
// iterations), with the comma before the kernel's own.
std::string KernelWayParam(const Kernel& k);
// The ISPC class's host data (IspcCode.cpp): the members it passes, its kernels' chunks and reductions.
void IspcHostData(const ClassModel& model, Data& d);

}  // namespace crossrt::engine
