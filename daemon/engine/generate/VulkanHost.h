// The host code's data for the templates: per control function its ...Cmd recording (Vulkan) and
// its body (CPU), per Vulkan kernel its pipeline, bindings and dispatch, and the buffers and images
// the Vulkan class holds.
#pragma once
#include "generate/CodeGen.h"
#include "generate/CodeGenSupport.h"

#include <kainjow/mustache.hpp>

#include <set>
#include <string>
#include <vector>

namespace crossrt::engine {

Data ControlsData(const ClassModel& model);

Data VulkanKernelsData(const ClassModel& model, unsigned& indirectSlots);

// Image2D and LiteImage::Sampler members kernels use, and the (image, sampler) pairs they sample.
Data ImagesData(const ClassModel& model, MemberKind kind);

Data VectorsData(const ClassModel& model);

}  // namespace crossrt::engine
