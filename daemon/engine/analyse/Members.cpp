// The class's data members: which become buffers (std::vector), class data, images, samplers,
// textures or vectors of objects, with their C++ and GLSL types. Takes the class; fills model.members
// and model.constructors.
#include "analyse/Members.h"

#include "analyse/AnalysisContext.h"
#include "analyse/AstQueries.h"
#include "generate/GeneratedNames.h"
#include "print/Printers.h"

#include <algorithm>
#include <set>

using namespace clang;

namespace crossrt::engine {

bool IsArrayOf3Vectors(QualType t) {
  auto* arr = dyn_cast<ConstantArrayType>(t.getCanonicalType().getTypePtr());
  if (!arr) return false;
  QualType e = arr->getElementType().getCanonicalType();
  return IsLiteMathType(e, "float3") || IsLiteMathType(e, "int3") || IsLiteMathType(e, "uint3");
}

bool FitsClassData(ASTContext& ctx, QualType t) {
  t = t.getCanonicalType();
  if (IsArrayOf3Vectors(t)) return true;
  if (IsLiteMathType(t)) return !IsLiteMathType(t, "float3x3");
  if (t->isBuiltinType() || t->isEnumeralType()) return Std430Layout(ctx, t, false).has_value();
  return LayoutMatchesCpp(ctx, t, false);
}

namespace {

// A destructor Clang has not declared yet (an implicit one) is virtual when a base's is.
bool HasVirtualDestructor(const CXXRecordDecl* rd) {
  if (auto* dtor = rd->getDestructor()) return dtor->isVirtual();
  for (auto& base : rd->bases())
    if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition() && HasVirtualDestructor(b->getDefinition())) return true;
  return false;
}

// A double (not an array of them) that an ISPC class keeps as double (the GPU has none).
bool IspcDouble(const Context& c, QualType t) { return c.model.forIspc && t.getCanonicalType()->isSpecificBuiltinType(BuiltinType::Double); }

}  // namespace

// A CRT_SPECIALIZE member must have a type a specialization constant holds: bool, or a 32-bit int,
// unsigned int, float or enum of one of those.
bool CheckSpecialized(Reporter& rep, const FieldDecl* f) {
  QualType t = f->getType().getCanonicalType().getUnqualifiedType();
  if (auto* e = t->getAs<EnumType>()) t = e->getDecl()->getIntegerType().getCanonicalType();
  if (t->isSpecificBuiltinType(BuiltinType::Bool) || t->isSpecificBuiltinType(BuiltinType::Int) ||
      t->isSpecificBuiltinType(BuiltinType::UInt) || t->isSpecificBuiltinType(BuiltinType::Float))
    return true;
  rep.RecordingError(f->getLocation(), "member '" + f->getNameAsString() + "' is CRT_SPECIALIZE but of type '" +
                     f->getType().getAsString(f->getASTContext().getPrintingPolicy()) + "', which a specialization constant cannot hold",
                     "CRT_SPECIALIZE takes a bool, int, uint32_t, float or enum member");
  return false;
}

void AnalyzeMembers(Context& c) {
  std::unique_ptr<KernelPrinter> structPrinter = MakePrinter(c.model, c.ctx, c.cls, c.rep);
  KernelPrinter& structs = *structPrinter;
  // The generated Vulkan class keeps its GPU objects in members of these names: a data member of
  // the same name would be hidden by them.
  static const std::set<std::string> generatedMembers = {
      generated::kVectorCopies, generated::kTemporaries,    generated::kThreadState, generated::kScanner,
      generated::kSorter,       generated::kVirtualObjects, generated::kImages,      generated::kTextures,
      generated::kPartials,     generated::kPipelines,      generated::kClassData,   generated::kPipelineConstants};
  for (auto* f : ClassFields(c.cls)) {
    Member m;
    m.name = f->getNameAsString();
    m.specialized = IsSpecializedMember(f) && CheckSpecialized(c.rep, f);
    if (!c.model.forCpu && (generatedMembers.count(m.name) || m.name.rfind(generated::kInOutPrefix, 0) == 0))
      c.rep.Error(f->getLocation(), "data member '" + m.name + "' has the name of a member the generated " + c.cls->getNameAsString() +
                                        "_Vulkan class declares for its GPU objects",
                  "rename it; the generated class's own members are crt_vdata, crt_temporaries, crt_threadState, crt_inOut_*, crt_scanner, "
                  "crt_sorter, crt_virtual, crt_images, crt_textureArrays, crt_partials, crt_pipelines and crt_classDataBuffer");
    m.hostExpr = m.name;
    QualType elem;
    if (IsTextureArray(f->getType(), &elem)) {
      auto format = TextureArrayFormat(f->getType());
      if (!format || format->texel == "uint") continue;  // reported if a kernel uses it
      m.kind = MemberKind::TextureArray;
      m.glslType = format->texel;
      m.vkFormat = format->vkFormat;
      m.combinedSamplers = IsCombinedSamplers(f->getType(), &m.singleTexture);
      m.elemCppType = m.combinedSamplers ? "LiteMath::float4" : CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsImage2D(f->getType(), &elem)) {
      auto format = ImageFormatOf(elem);
      if (!format) continue;  // reported if a kernel uses it
      m.kind = MemberKind::Image;
      m.glslType = format->texel;
      m.imageFormat = format->glslFormat;
      m.vkFormat = format->vkFormat;
      m.imagePrefix = format->prefix;
      m.elemCppType = CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsImageSampler(f->getType())) {
      m.kind = MemberKind::Sampler;
      m.cppType = CppTypeName(c.ctx, f->getType());
    } else if (IsStdVector(f->getType(), &elem)) {
      auto g = IspcDouble(c, elem) ? std::optional<std::string>("double") : GlslTypeOf(elem);
      if (!g) continue;  // reported if a kernel uses it
      m.kind = MemberKind::Vector;
      m.glslType = *g;
      m.elemCppType = CppTypeName(c.ctx, elem);
      m.cppType = CppTypeName(c.ctx, f->getType());
      m.scalarLayout = !LayoutMatchesCpp(c.ctx, elem, false);
      if (f->getAccess() != AS_private && (!m.scalarLayout || LayoutMatchesCpp(c.ctx, elem, true))) structs.Type(elem, f->getLocation());
    } else {
      auto g = IspcDouble(c, f->getType()) ? std::optional<std::string>("double") : GlslTypeOf(f->getType());
      if (!g) continue;
      m.kind = MemberKind::Plain;
      m.glslType = *g;
      QualType base = f->getType();
      while (auto* arr = dyn_cast<ConstantArrayType>(base.getCanonicalType().getTypePtr())) base = arr->getElementType();
      m.cppType = CppTypeName(c.ctx, base);
      m.padded3 = IsArrayOf3Vectors(f->getType());
      m.inClassData = f->getAccess() != AS_private && (*g == "double" || FitsClassData(c.ctx, f->getType()));  // ISPC's double: as in C++
      if (auto layout = Std430Layout(c.ctx, f->getType(), false)) m.std430Align = unsigned(layout->align);
      if (m.inClassData) structs.Type(f->getType(), f->getLocation());
    }
    c.model.members.push_back(m);
  }
  c.model.glslClassStructs = structs.PreludeTypes();
  for (auto& s : structs.Structs()) c.model.glslClassStructNames.insert(s.name);
  for (auto* ctor : c.cls->ctors()) {
    if (ctor->isImplicit() || ctor->isCopyOrMoveConstructor() || ctor->isDeleted() || ctor->getAccess() == AS_private) continue;
    Constructor k;
    // Default arguments, for the declarations (the generated constructor and factories): as
    // written, over the longest run of trailing parameters whose defaults name nothing in a
    // class's scope, which the factories (free functions) could not see.
    struct ClassScoped : RecursiveASTVisitor<ClassScoped> {
      bool found = false;
      bool VisitDeclRefExpr(DeclRefExpr* dr) {
        found = found || dr->getDecl()->getDeclContext()->isRecord();
        return true;
      }
    };
    unsigned firstDefault = ctor->getNumParams();
    while (firstDefault > 0) {
      const ParmVarDecl* p = ctor->getParamDecl(firstDefault - 1);
      if (!p->hasDefaultArg() || p->hasUninstantiatedDefaultArg() || p->hasUnparsedDefaultArg()) break;
      ClassScoped scoped;
      scoped.TraverseStmt(const_cast<Expr*>(p->getDefaultArg()));
      if (scoped.found) break;
      --firstDefault;
    }
    for (unsigned i = 0; i < ctor->getNumParams(); ++i) {
      const ParmVarDecl* p = ctor->getParamDecl(i);
      const std::string decl = ParamDecl(c.ctx, p, i);
      k.paramsDecl += (i ? ", " : "") + decl;
      k.paramsWithDefaults += (i ? ", " : "") + decl + (i >= firstDefault ? " = " + c.Text(p->getDefaultArgRange()) : "");
      std::string n = p->getNameAsString();
      k.argsForward += (i ? ", " : "") + (n.empty() ? "a_unnamed" + std::to_string(i) : n);
    }
    c.model.constructors.push_back(k);
  }
  if (c.model.constructors.empty()) c.model.constructors.push_back({});
  c.model.virtualDestructor = HasVirtualDestructor(c.cls);
  for (auto* md : ClassMethods(c.cls)) {
    if (md->getName() == "CommitDeviceData" && md->isVirtual()) c.model.declaresCommitDeviceData = true;
    if (md->getName() == "GetExecutionTime" && md->isVirtual()) c.model.declaresGetExecutionTime = true;
  }
}

std::set<std::string> ClassStructNames(const ClassModel& model) { return model.glslClassStructNames; }

}  // namespace crossrt::engine
