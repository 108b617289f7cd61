// Virtual calls through std::vector<Interface*> members (paper 3.9): finds the implementations of the
// interface, lays out each one's data as the GPU mirrors it, and records the calls a kernel makes.
#include "VirtualCalls.h"

#include "AnalysisContext.h"
#include "Callables.h"

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

std::string ImplementationMethod(Reporter& rep, GlslPrinter& printer, const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc) {
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
  return p->getName().empty() ? "arg" + std::to_string(i) : GlslPrinter::SafeName(p->getNameAsString());
}

bool WrittenBack(const CXXMethodDecl* m, unsigned i) {
  QualType pt = m->getParamDecl(i)->getType();
  return pt->isReferenceType() && !pt.getNonReferenceType().isConstQualified();
}

std::string DispatcherParams(GlslPrinter& printer, const CXXMethodDecl* m) {
  std::string out;
  for (unsigned i = 0; i < m->getNumParams(); ++i)
    out += std::string(", ") + (WrittenBack(m, i) ? "inout " : "") +
           printer.Declare(m->getParamDecl(i)->getType(), CallArgumentName(m, i), m->getParamDecl(i)->getLocation());
  return out;
}

GlslDecl TagsReference(const ClassModel& model, const VirtualMember& vm) {
  return {vm.member + "_Tags", "layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer " + vm.member + "_Tags { uvec2 tags[]; };  // per element of " +
         vm.display + ": (class, " + (model.virtualLevel == 1 ? "its slot" : "index among its class's objects") + ")\n"};
}

GlslDecl ImplDataStruct(GlslPrinter& printer, const CXXRecordDecl* impl, const VirtualMember& vm, const VirtualImpl& vi) {
  std::ostringstream data;
  data << "struct " << vi.name << "_Data {  // the data members of " << vi.name << "\n";
  std::vector<const FieldDecl*> fields;
  CollectObjectFields(impl, fields);
  for (auto* f : fields) data << "  " << printer.Declare(f->getType(), GlslPrinter::SafeName(f->getNameAsString()), f->getLocation()) << ";\n";
  if (vi.paddingWords > 0)
    data << "  uint crt_padding[" << vi.paddingWords << "];  // every element of a vector of " << vm.interfaceName << " has a slot of " << vm.slotBytes
         << " bytes\n";
  data << "};\n";
  return {vi.name + "_Data", data.str()};
}

GlslDecl ObjectsReference(const VirtualMember& vm, const VirtualImpl& vi) {
  return {vm.member + "_" + vi.name + "Objects", std::string("layout(buffer_reference, ") + (vi.scalarLayout ? "scalar" : "std430") + ", buffer_reference_align = 4) readonly buffer " +
         vm.member + "_" + vi.name + "Objects { " + vi.name + "_Data objects[]; };\n"};
}

void CheckObjectSizeReads(Reporter& rep, const GlslPrinter& printer) {
  for (auto& [field, loc] : printer.Uses().objectSizeReads)
    if (std::none_of(printer.Uses().virtualCalls.begin(), printer.Uses().virtualCalls.end(), [&](const auto& call) { return call.first == field; }))
      rep.GpuError(loc, "the kernel reads the size of '" + field->getNameAsString() + "', a vector of objects it calls no virtual function through",
                "keep the count in a plain member, or read the size where the kernel also calls through the vector");
}

void AnalyzeVirtualCalls(Context& c, Kernel& k, GlslPrinter& kernelPrinter) {
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
