// Virtual calls through std::vector<Interface*> members (paper 3.9): finds the implementations of the
// interface, lays out each one's data as the GPU mirrors it, and records the calls a kernel makes.
#include "analyse/VirtualCalls.h"
#include "generate/CodeGenSupport.h"

#include "analyse/AnalysisContext.h"
#include "analyse/Callables.h"
#include "print/ispc/IspcTypes.h"

#include <algorithm>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

void FindImplementations(const DeclContext* dc, const CXXRecordDecl* interface, std::vector<const CXXRecordDecl*>& out) {
  for (auto* d : dc->decls()) {
    if (auto* ns = dyn_cast<NamespaceDecl>(d); ns && !ns->isStdNamespace() && !IsSystemDecl(ns)) FindImplementations(ns, interface, out);
    auto* rd = dyn_cast<CXXRecordDecl>(d);
    if (!rd || !rd->isThisDeclarationADefinition() || IsSystemDecl(rd) || rd->isAbstract() || rd->isDependentContext()) continue;
    if (rd->isDerivedFrom(interface)) out.push_back(rd);
    FindImplementations(rd, interface, out);  // nested classes
  }
}

void CollectObjectFields(const CXXRecordDecl* rd, std::vector<const FieldDecl*>& out) {
  for (auto& base : rd->bases())
    if (auto* b = base.getType()->getAsCXXRecordDecl(); b && b->hasDefinition()) CollectObjectFields(b->getDefinition(), out);
  for (auto* f : rd->fields()) out.push_back(f);
}

std::optional<std::vector<uint64_t>> MirrorOffsets(ASTContext& ctx, const std::vector<const FieldDecl*>& fields, int layout /* 0 C++, 1 std430, 2 scalar */) {
  std::vector<uint64_t> offsets;
  uint64_t offset = 0, align = 1;
  for (auto* f : fields) {
    uint64_t a, size;
    if (layout == 0) {
      a = ctx.getTypeAlignInChars(f->getType()).getQuantity();
      size = ctx.getTypeSizeInChars(f->getType()).getQuantity();
    } else {
      auto l = Std430Layout(ctx, f->getType(), layout == 2);
      if (!l) return std::nullopt;
      a = l->align;
      size = l->size;
    }
    offset = (offset + a - 1) / a * a;
    offsets.push_back(offset);
    offset += size;
    align = std::max(align, a);
  }
  offsets.push_back((offset + align - 1) / align * align);  // the array stride
  return offsets;
}

std::string ImplementationMethod(Reporter& rep, KernelPrinter& printer, const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc) {
  const CXXMethodDecl* overrider = method->getCorrespondingMethodInClass(impl);
  const FunctionDecl* def = nullptr;
  if (!overrider || overrider->isPureVirtual() || !overrider->hasBody(def) || !def) {
    rep.GpuError(callLoc, "the GPU needs the body of " + impl->getNameAsString() + "'s " + method->getNameAsString() +
                " (kernels call it through virtual functions), but this translation unit does not define it",
                "define it in the header that declares " + impl->getNameAsString() + ", or in the class's source file");
    return "";
  }
  return printer.EmitComposedMethod(overrider);
}

void RequireReachable(Reporter& rep, const FieldDecl* f, const CXXRecordDecl* cls) {
  if (f->getAccess() == AS_private)
    rep.Error(f->getLocation(), "member '" + f->getNameAsString() + "' is private, but the generated class derives from '" + cls->getNameAsString() + "' and must reach it",
              "declare it protected");
}

void RequirePublicForComposition(Reporter& rep, const FieldDecl* f, const std::string& implName, const std::string& how) {
  if (f->getAccess() != AS_public)
    rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of " + implName + " is read on the GPU through composition" + how +
              ", so the generated class must reach it through a " + implName + "*", "declare it public");
}

std::string CallArgumentName(const CXXMethodDecl* m, unsigned i) {
  const ParmVarDecl* p = m->getParamDecl(i);
  return p->getName().empty() ? "arg" + std::to_string(i) : KernelPrinter::SafeName(p->getNameAsString());
}

bool WrittenBack(const CXXMethodDecl* m, unsigned i) {
  QualType pt = m->getParamDecl(i)->getType();
  if (pt->isPointerType()) return !pt->getPointeeType().isConstQualified();  // CRT_Hit* pHit: the one value it points at
  return pt->isReferenceType() && !pt.getNonReferenceType().isConstQualified();
}

QualType PassedType(const CXXMethodDecl* m, unsigned i) {
  QualType pt = m->getParamDecl(i)->getType();
  return (pt->isPointerType() ? pt->getPointeeType() : pt.getNonReferenceType()).getUnqualifiedType();
}

std::string DispatcherParams(KernelPrinter& printer, const CXXMethodDecl* m, bool forIspc) {
  std::string out;
  for (unsigned i = 0; i < m->getNumParams(); ++i) {
    if (KernelPrinter::PointsTo(m->getParamDecl(i)->getType(), printer.Class())) continue;  // the caller, left out (print/Owner.cpp)
    std::string declared = printer.Declare(PassedType(m, i), CallArgumentName(m, i), m->getParamDecl(i)->getLocation());
    if (WrittenBack(m, i) && forIspc) declared.insert(declared.rfind(' ') + 1, "&");  // ISPC: a reference
    else if (WrittenBack(m, i)) declared = "inout " + declared;
    out += ", " + declared;
  }
  return out;
}

// The declarations of a vector of objects' GLSL (templates/glsl/virtual_objects.glsl.mustache): its
// tags, a class's data struct, the buffer reference to a class's objects.
GlslDecl TagsReference(const ClassModel& model, const VirtualMember& vm) {
  Data d;
  d.set("tags", true);
  d.set("member", vm.member);
  d.set("display", vm.display);
  d.set("tagMeaning", model.virtualLevel == 1 ? "its slot" : "index among its class's objects");
  return {vm.member + "_Tags", Render(model.templateDir + "/glsl/virtual_objects.glsl.mustache", d)};
}

std::vector<GlslDecl> ClassConstants(const ClassModel& model, const VirtualMember& vm) {
  std::vector<GlslDecl> out;
  for (size_t t = 0; t < vm.impls.size(); ++t) {
    Data d, constant;
    constant.set("id", std::to_string(kClassConstantIdBase + vm.firstClassConstant + t));
    constant.set("name", ClassConstantName(vm, t));
    constant.set("class", vm.impls[t].name);
    constant.set("display", vm.display);
    d.set("classConstant", constant);
    out.push_back({ClassConstantName(vm, t), Render(model.templateDir + "/glsl/virtual_objects.glsl.mustache", d)});
  }
  return out;
}

std::string ClassConstantName(const VirtualMember& vm, size_t t) { return "crt_" + vm.member + "_holds" + vm.impls[t].name; }

GlslDecl ImplDataStruct(const ClassModel& model, KernelPrinter& printer, const CXXRecordDecl* impl, const VirtualMember& vm, const VirtualImpl& vi) {
  Data d, fields = List();
  d.set("data", true);
  d.set("class", vi.name);
  d.set("dataStruct", model.forIspc ? IspcObjectStruct(vi.cppName) : vi.name + "_Data");
  std::vector<const FieldDecl*> members;
  CollectObjectFields(impl, members);
  for (auto* f : members) {
    Data x;
    x.set("declaration", printer.Declare(f->getType(), KernelPrinter::SafeName(f->getNameAsString()), f->getLocation()));
    fields.push_back(x);
  }
  d.set("fields", fields);
  if (vi.paddingWords > 0) d.set("paddingWords", std::to_string(vi.paddingWords));
  else d.set("paddingWords", false);
  d.set("interface", vm.interfaceName);
  d.set("slotBytes", std::to_string(vm.slotBytes));
  return {model.forIspc ? IspcObjectStruct(vi.cppName) : vi.name + "_Data", Render(model.templateDir + (model.forIspc ? "/ispc/virtual_objects.ispc.mustache" : "/glsl/virtual_objects.glsl.mustache"), d)};
}

GlslDecl ObjectsReference(const ClassModel& model, const VirtualMember& vm, const VirtualImpl& vi) {
  Data d;
  d.set("objects", true);
  d.set("member", vm.member);
  d.set("class", vi.name);
  d.set("layout", vi.scalarLayout ? "scalar" : "std430");
  return {vm.member + "_" + vi.name + "Objects", Render(model.templateDir + "/glsl/virtual_objects.glsl.mustache", d)};
}

void CheckObjectSizeReads(Reporter& rep, const KernelPrinter& printer) {
  for (auto& [field, loc] : printer.Uses().objectSizeReads)
    if (std::none_of(printer.Uses().virtualCalls.begin(), printer.Uses().virtualCalls.end(), [&](const auto& call) { return call.first == field; }))
      rep.GpuError(loc, "the kernel reads the size of '" + field->getNameAsString() + "', a vector of objects it calls no virtual function through",
                "keep the count in a plain member, or read the size where the kernel also calls through the vector");
}

void AnalyzeVirtualCalls(Context& c, Kernel& k, KernelPrinter& kernelPrinter) {
  std::vector<GlslDecl> structs;
  std::vector<std::string> functions;
  CallableCode callable;
  VirtualCallCode(c.ctx, c.rep, c.model, k, kernelPrinter, VirtualOwner{c.cls, "", "", ""}, structs, functions,
                  c.model.virtualLevel == 3 ? &callable : nullptr);
  if (c.model.virtualLevel == 3) {
    // The ray generation shader needs the tags, not the implementations' code or data.
    k.callableStructList = k.structList;
    for (auto& x : callable.structs) k.callableStructList.push_back(x);
    k.callableFunctionList = callable.functions;
    for (auto& x : k.functionList) k.callableFunctionList.push_back(x);
  }
  // Ahead of the kernel's own code, which calls the dispatchers.
  for (auto& x : structs)
    if (std::find(k.structList.begin(), k.structList.end(), x) == k.structList.end()) k.structList.push_back(x);
  // Free functions both print are the same text: keep the first.
  std::vector<std::string> merged;
  for (auto* list : {&functions, &k.functionList})
    for (auto& x : *list)
      if (std::find(merged.begin(), merged.end(), x) == merged.end()) merged.push_back(x);
  k.functionList = merged;
}

}  // namespace crossrt::engine
