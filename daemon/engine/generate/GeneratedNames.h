// The members of the generated Vulkan class that the engine writes into host code (the ...Cmd
// bodies of control functions, kernels' bindings): declared once here. templates/vulkan/class.h.mustache
// declares the members under these names, and test/engine/test_generated_names.cpp checks that it does.
#pragma once
#include <string>

namespace crossrt::engine::generated {

inline const std::string kVectorCopies = "crt_vdata";         // device copies of std::vector members
inline const std::string kTemporaries = "crt_temporaries";    // device buffers of std::vector locals of control functions
inline const std::string kThreadState = "crt_threadState";    // per-thread locals of thread loops between wavefront dispatches
inline const std::string kInOutPrefix = "crt_inOut_";         // + control function: its pointer arguments' device buffers
inline const std::string kScanner = "crt_scanner";            // std::exclusive_scan / inclusive_scan on the GPU
inline const std::string kSorter = "crt_sorter";              // std::sort on the GPU
inline const std::string kVirtualObjects = "crt_virtual";     // vectors of objects regrouped for virtual calls
inline const std::string kImages = "crt_images";              // Image2D members and samplers
inline const std::string kTextures = "crt_textureArrays";     // arrays of textures
inline const std::string kPartials = "crt_partials";          // per-workgroup partial results of reductions
inline const std::string kPipelines = "crt_pipelines";        // one per shader
inline const std::string kClassData = "crt_classDataBuffer";  // the class data block
inline const std::string kPipelineConstants = "crt_pipelineConstants";  // the specialization the pipelines were made with

// Names derived from the user's names carry the reserved prefix too, so that none can equal a user's
// name (analyse/ReservedNames.cpp refuses user names under it): a member vector's size and capacity
// in the class data (GLSL, ISPC and C++), an image's size (in the class data for a member, in the
// push constants for a parameter) and its texture in GLSL, and the GLSL blocks that hold a buffer.
inline std::string SizeField(const std::string& vector) { return "crt_" + vector + "_size"; }
inline std::string CapacityField(const std::string& vector) { return "crt_" + vector + "_capacity"; }
inline std::string ImageSizeField(const std::string& image, const std::string& widthOrHeight) { return "crt_" + image + "_" + widthOrHeight; }
inline std::string TextureName(const std::string& image) { return "crt_" + image + "_texture"; }
inline std::string BlockName(const std::string& variable) { return "crt_" + variable + "Buffer"; }
// A CRT_SPECIALIZE member (Specialize.h) as GLSL reads it: a specialization constant.
inline std::string SpecializedConstant(const std::string& member) { return "crt_" + member + "_specialized"; }
// A reduction of `member` (a member or a kernel local): the per-thread (per-lane, per-chunk) copy the
// loop body adds to, the workgroup's shared array, one workgroup's total, and the per-workgroup (per
// chunk) totals. templates/glsl/{kernel,reduce}.comp, ispc/kernels.ispc and cpu/class.cpp write the
// same names as crt_{{member}}Local, ...Shared, ...Group and ...Partials.
inline std::string ReductionLocal(const std::string& member) { return "crt_" + member + "Local"; }
inline std::string ReductionShared(const std::string& member) { return "crt_" + member + "Shared"; }
inline std::string ReductionGroup(const std::string& member) { return "crt_" + member + "Group"; }
inline std::string ReductionPartials(const std::string& member) { return "crt_" + member + "Partials"; }
// A vector of objects with virtual functions, in the class data (GLSL, ISPC): each element's class
// and slot, the slots of all classes (level 1) and each class's objects (level 2 and ISPC). The
// templates write crt_{{member}}_tags and crt_{{member}}_{{impl}}.
inline std::string VirtualTagsField(const std::string& vector) { return "crt_" + vector + "_tags"; }
inline std::string VirtualSlotsField(const std::string& vector) { return "crt_" + vector + "_objects"; }
inline std::string VirtualClassField(const std::string& vector, const std::string& impl) { return "crt_" + vector + "_" + impl; }
// The function that calls `method` on an element of such a vector, whichever its class (GLSL, ISPC;
// the templates' dispatchers are crt_{{member}}_{{method}}).
inline std::string VirtualDispatcher(const std::string& vector, const std::string& method) { return "crt_" + vector + "_" + method; }
// An _ISPC class's kernel runs one of two methods, whichever has been faster (crossrt::LaneChoice):
// its loop nest as ISPC, in SIMD lanes, or its loop nest as the _CPU class runs it.
inline std::string LanesMethod(const std::string& kernel) { return "crt_" + kernel + "_InLanes"; }
inline std::string ScalarMethod(const std::string& kernel) { return "crt_" + kernel + "_Scalar"; }

}  // namespace crossrt::engine::generated
