// The members of the generated Vulkan class that the engine writes into host code (the ...Cmd
// bodies of control functions, kernels' bindings): declared once here. templates/vulkan/class.h.mustache
// declares the members under these names, and test/engine/test_generated_names.cpp checks that it does.
#pragma once
#include <string>

namespace crossrt::engine::generated {

inline const std::string kVectorCopies = "m_vdata";         // device copies of std::vector members
inline const std::string kTemporaries = "m_temporaries";    // device buffers of std::vector locals of control functions
inline const std::string kThreadState = "m_threadState";    // per-thread locals of thread loops between wavefront dispatches
inline const std::string kInOutPrefix = "m_inOut_";         // + control function: its pointer arguments' device buffers
inline const std::string kScanner = "m_scanner";            // std::exclusive_scan / inclusive_scan on the GPU
inline const std::string kSorter = "m_sorter";              // std::sort on the GPU
inline const std::string kVirtualObjects = "m_virtual";     // vectors of objects regrouped for virtual calls
inline const std::string kImages = "m_images";              // Image2D members and samplers
inline const std::string kTextures = "m_textureArrays";     // arrays of textures
inline const std::string kPartials = "m_partials";          // per-workgroup partial results of reductions
inline const std::string kPipelines = "m_pipelines";        // one per shader
inline const std::string kClassData = "m_classDataBuffer";  // the class data block
inline const std::string kPipelineClasses = "m_pipelineClasses";  // the classes the pipelines switch over

}  // namespace crossrt::engine::generated
