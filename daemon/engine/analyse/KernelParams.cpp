// A kernel's parameters: which are buffers (size-annotated pointers), images, thread ids or values,
// and what each becomes in GLSL and in the ...Cmd signature. Reports the ones that cannot be bound.
#include "analyse/KernelParams.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "analyse/Members.h"
#include "analyse/Naming.h"

#include <algorithm>
#include <cctype>

using namespace clang;

namespace crossrt::engine {

bool IsImageParam(const ParmVarDecl* p) {
  return p->getType()->isReferenceType() && IsImage2D(p->getType().getNonReferenceType().getUnqualifiedType());
}

void CheckKernelParams(Context& c, const CXXMethodDecl* md, const FunctionDecl* def, Kernel& k) {
  for (unsigned i = 0; i < md->getNumParams(); ++i) {
    auto* p = md->getParamDecl(i);
    KernelParam kp;
    kp.name = def->getParamDecl(i)->getNameAsString();  // the name the body uses
    // A parameter the definition leaves unnamed (unused there) takes the declaration's name (tidX
    // still names a thread id), or one of its own.
    if (kp.name.empty()) kp.name = p->getName().empty() ? "crt_unnamed" + std::to_string(i) : p->getNameAsString();
    kp.glslName = KernelPrinter::SafeName(kp.name);
    QualType t = p->getType();
    kp.isThreadId = k.rtv && IsThreadIdName(kp.name);
    QualType texel;
    if (IsImage2D(t.getNonReferenceType().getUnqualifiedType(), &texel)) {
      auto format = ImageFormatOf(texel);
      if (!t->isReferenceType()) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' takes an Image2D by value",
                    "take it by reference: 'const Image2D<T>& " + kp.name + "' to read it, 'Image2D<T>& " + kp.name + "' to write it");
        continue;
      }
      if (!format) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' is an Image2D of '" + texel.getAsString(c.ctx.getPrintingPolicy()) + "', which GPU images cannot hold",
                    "use Image2D<float4>, Image2D<float> or Image2D<uint32_t>");
        continue;
      }
      kp.isImage = true;
      kp.isConstPointee = t.getNonReferenceType().isConstQualified();
      kp.glslType = format->texel;
      kp.imageFormat = format->glslFormat;
      kp.imagePrefix = format->prefix;
      k.params.push_back(kp);
      continue;
    }
    if (t->isPointerType()) {
      QualType pointee = t->getPointeeType();
      kp.isPointer = true;
      kp.threadState = k.rtv && c.threadState.count({k.name, kp.name});
      kp.isConstPointee = pointee.isConstQualified();
      auto g = GlslTypeOf(pointee);
      if (c.model.forIspc && pointee->isSpecificBuiltinType(BuiltinType::Double)) {  // ISPC has C's double
        kp.glslType = "double";
        k.params.push_back(kp);
        continue;
      }
      if (pointee->isRealFloatingType() && !pointee->isSpecificBuiltinType(BuiltinType::Float)) {
        c.rep.GpuError(p->getLocation(), DoubleRefusal(pointee.getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy())), DoubleRefusalHint());
        continue;
      }
      if (!g || pointee->isPointerType()) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' points to '" + pointee.getAsString(c.ctx.getPrintingPolicy()) + "', which has no GPU equivalent",
                    "pass arrays of int, uint, float, LiteMath vectors or plain structs of those");
        continue;
      }
      kp.glslType = *g;
      if (!LayoutMatchesCpp(c.ctx, pointee, false)) {
        if (LayoutMatchesCpp(c.ctx, pointee, true)) kp.scalarLayout = true;
        else c.rep.GpuError(p->getLocation(), "the C++ layout of '" + pointee.getAsString(c.ctx.getPrintingPolicy()) + "' cannot be reproduced in a GPU buffer",
                         "reorder the fields so 16-byte types (float4, float3) come first, or pad them to float4");
      }
    } else if (t->isReferenceType() && !t.getNonReferenceType().isConstQualified()) {
      c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' is a non-const reference",
                  "kernels return results through pointer parameters or members");
    } else {
      auto g = GlslTypeOf(t);
      if (c.model.forIspc && t.getNonReferenceType()->isSpecificBuiltinType(BuiltinType::Double)) g = "double";
      else if (t.getNonReferenceType()->isRealFloatingType() && !t.getNonReferenceType()->isSpecificBuiltinType(BuiltinType::Float)) {
        c.rep.GpuError(p->getLocation(), DoubleRefusal(t.getNonReferenceType().getUnqualifiedType().getAsString(c.ctx.getPrintingPolicy())), DoubleRefusalHint());
        continue;
      }
      if (!g) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) + "' has no GPU equivalent",
                    "use int, uint, float, LiteMath types, plain structs, or a pointer with a size");
        continue;
      }
      QualType value = t.getNonReferenceType().getUnqualifiedType();
      // 64-bit integers (size_t, int64_t) are 32-bit in shaders, like loop counters of those types.
      if (value->isIntegerType() && c.ctx.getTypeSize(value) == 64) {
        kp.glslType = *g;
        kp.std430Align = 4;
        kp.valueCppType = value->isUnsignedIntegerType() ? "uint32_t" : "int32_t";
        kp.narrowed = true;
        kp.cppType = ParamDecl(c.ctx, p, i);
        kp.cppType = kp.cppType.substr(0, kp.cppType.size() - p->getName().size());
        while (!kp.cppType.empty() && isspace((unsigned char)kp.cppType.back())) kp.cppType.pop_back();
        if (c.rep.GpuRules())
          c.rep.Note(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) +
                     "' is 32-bit on the GPU: values above " + std::string(value->isUnsignedIntegerType() ? "4294967295" : "2147483647") + " wrap around");
        k.params.push_back(kp);
        continue;
      }
      auto layout = *g == "double" ? std::optional<LayoutInfo>(LayoutInfo{8, 8}) : Std430Layout(c.ctx, value, false);
      if (!layout || !FitsClassData(c.ctx, value)) {
        c.rep.GpuError(p->getLocation(), "kernel parameter '" + kp.name + "' of type '" + t.getAsString(c.ctx.getPrintingPolicy()) + "' cannot be passed to the GPU as it is laid out in C++",
                    "use 32-bit int, uint or float, LiteMath vectors, float4x4, or structs whose fields keep the std430 layout (bool is 1 byte in C++, 4 on the GPU: use int)");
        continue;
      }
      kp.std430Align = unsigned(layout->align);
      kp.glslType = *g;
      kp.valueCppType = CppTypeName(c.ctx, value);
      kp.cppType = ParamDecl(c.ctx, p, i);
      kp.cppType = kp.cppType.substr(0, kp.cppType.size() - p->getName().size());  // type part only
      while (!kp.cppType.empty() && isspace((unsigned char)kp.cppType.back())) kp.cppType.pop_back();
    }
    k.params.push_back(kp);
  }
}

}  // namespace crossrt::engine
