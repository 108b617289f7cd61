// C++ types as GLSL sees them: spellings, what images, samplers, textures and vectors hold, and the
// std430 and scalar layouts a buffer may use to reproduce a C++ layout exactly.
#pragma once
#include <clang/AST/ASTContext.h>
#include <clang/AST/DeclCXX.h>
#include <clang/AST/DeclTemplate.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

namespace crossrt::engine {

// GLSL spelling of a C++ type, or nullopt when it has none (the caller reports).
// Arrays come back as "float[4]"; use SplitArray() to declare a variable.
std::optional<std::string> GlslTypeOf(clang::QualType type);
// "float[4]" -> {"float", "[4]"}
std::pair<std::string, std::string> SplitArray(const std::string& glslType);

bool IsLiteMathType(clang::QualType type, const char* name = nullptr);
bool IsStdVector(clang::QualType type, clang::QualType* element = nullptr);
// std::array<T, N>, which kernels hold as T[N], and its T and N.
bool IsStdArray(clang::QualType type, clang::QualType* element = nullptr, uint64_t* size = nullptr);
// Image2D<T> (any namespace, as the paper's LiteImage names it) and its texel type.
bool IsImage2D(clang::QualType type, clang::QualType* texel = nullptr);
// LiteImage::Sampler: filtering and address modes of image samples.
bool IsImageSampler(clang::QualType type);
// A member kernels sample as an array of textures (combined image samplers): a
// std::vector<LiteImage::Texture2D<T>> (and T), or kernel_slicer's form, a std::vector of
// shared_ptr, unique_ptr or plain pointers to LiteImage::ICombinedImageSampler, or one such pointer
// (an array of one texture). Those read float4 texels, whatever their images hold; `texel` stays null.
bool IsTextureArray(clang::QualType type, clang::QualType* texel = nullptr);
// kernel_slicer's form of the above; `single` tells one pointer from a vector of them.
bool IsCombinedSamplers(clang::QualType type, bool* single = nullptr);
// A (smart) pointer to LiteImage::ICombinedImageSampler.
bool IsCombinedSamplerPointer(clang::QualType type);
// GPU image format of an Image2D<T>: GLSL format qualifier, Vulkan format, texel GLSL type,
// image/texture type prefix ("" or "u"); nullopt for texel types the GPU cannot hold.
struct ImageFormat { std::string glslFormat, vkFormat, texel, prefix; };
std::optional<ImageFormat> ImageFormatOf(clang::QualType texel);
// The format of an array of textures' texels (IsTextureArray): float4 for combined image samplers.
std::optional<ImageFormat> TextureArrayFormat(clang::QualType type);
bool IsSystemDecl(const clang::Decl* decl);
// Whether `d` is declared inside a namespace named `ns` (at any depth).
bool InNamespace(const clang::Decl* d, const char* ns);
// Why double is refused in Vulkan kernels, and what to do instead (by design: the GPU's limits).
std::string DoubleRefusal(const std::string& type);
std::string DoubleRefusalHint();
// std430 array stride of a scalar or vector GLSL type: "vec3" and "vec4" 16, "vec2" 8, scalars 4.
unsigned Std430VectorStride(const std::string& glslType);

// Memory layouts a GLSL buffer block can use. A C++ type can be shared with the GPU only when one
// of them gives exactly the C++ offsets and sizes.
struct LayoutInfo { uint64_t size = 0, align = 0; };
std::optional<LayoutInfo> Std430Layout(clang::ASTContext& ctx, clang::QualType type, bool scalar);
// True when an array of `type` in the given layout has the C++ stride and field offsets.
bool LayoutMatchesCpp(clang::ASTContext& ctx, clang::QualType type, bool scalar);

}  // namespace crossrt::engine
