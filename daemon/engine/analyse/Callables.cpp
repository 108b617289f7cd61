// The code of virtual calls: per implementation its data struct and methods printed with `self`, per
// method a dispatcher that switches over the object's class (levels 1-2), or at level 3 a callable
// shader per implementation and the call that the ray generation shader makes.
#include "analyse/Callables.h"
#include "generate/CodeGenSupport.h"
#include "generate/GeneratedNames.h"
#include "print/Printers.h"
#include "print/glsl/GlslPrinter.h"

#include "analyse/AstQueries.h"
#include "analyse/Members.h"
#include "analyse/VirtualCalls.h"

#include <algorithm>

using namespace clang;

namespace crossrt::engine {

namespace {

// Level 3: `vm`'s implementation `vi` (an object of class `impl`) of `method` as a callable shader,
// named <member>_<class>_<method>, added to the model unless another kernel added it. `payload`
// declares the incoming call.
void AddCallableShader(ASTContext& ctx, Reporter& rep, ClassModel& model, const VirtualMember& vm, const VirtualImpl& vi,
                       const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc, const std::string& dataStruct,
                       const std::string& objectsReference, const std::string& payload) {
  const std::string name = vm.member + "_" + vi.name + "_" + method->getNameAsString();
  if (std::any_of(model.callables.begin(), model.callables.end(), [&](const StageShader& c) { return c.name == name; })) return;
  GlslPrinter printer(ctx, impl, rep);  // a callable shader of the ray tracing pipeline
  printer.selfClass = impl;
  printer.composedPrefix = vi.name + "_";
  for (auto& sn : ClassStructNames(model)) printer.predeclaredStructs.insert(sn);
  const std::string function = ImplementationMethod(rep, printer, impl, method, callLoc);
  if (function.empty()) return;
  StageShader c;
  c.name = name;
  c.stage = "rcall";
  c.origin = vi.name + "::" + method->getNameAsString();
  c.description = "what " + vm.display + "[index]->" + method->getNameAsString() + (method->getNumParams() ? "(...)" : "()") +
                  " runs when the object is\n// a " + vi.name +
                  ", as a callable shader of the ray tracing pipelines of the kernels calling it (virtual functions, level 3)";
  c.scalarLayout = vi.scalarLayout;
  for (auto& x : printer.Constants()) c.constants += x.text;
  for (auto& x : printer.Structs()) c.structs += x.text + "\n";
  c.structs += dataStruct + "\n" + objectsReference + "\n" + payload;
  for (auto& x : printer.Functions()) c.functions += x + "\n";
  std::string args = "self";
  for (unsigned i = 0; i < method->getNumParams(); ++i) args += ", call." + CallArgumentName(method, i);
  const std::string invoke = function + "(" + args + ")";
  c.mainBody = "  const " + vi.name + "_Data self = " + vm.member + "_" + vi.name + "Objects(call.crt_objects).objects[call.crt_index];\n  " +
               (method->getReturnType()->isVoidType() ? invoke : "call.crt_result = " + invoke) + ";\n";
  model.callables.push_back(c);
}

// Level 3: `m` called through `vm` from a kernel's ray generation shader. Its payload, and a
// dispatcher that fills it and executes the callable shader of the object's class (numbered after
// the kernel's callables so far); each implementation's callable shader joins the model.
void CallableDispatcher(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, KernelPrinter& kernelPrinter, const VirtualMember& vm,
                        const std::vector<const CXXRecordDecl*>& impls, const CXXMethodDecl* m, SourceLocation callLoc,
                        const std::map<std::string, std::pair<GlslDecl, GlslDecl>>& implData, CallableCode& out) {
  const std::string method = m->getNameAsString(), callName = generated::VirtualDispatcher(vm.member, method), variable = callName + "_call";
  const std::string display = vm.display + "[index]->" + method + (m->getNumParams() ? "(...)" : "()");
  auto ret = kernelPrinter.Type(m->getReturnType(), m->getLocation());
  const std::string retType = ret ? *ret : "void";
  // The payload (templates/glsl/callable_payload.glsl.mustache): the call's arguments and result,
  // declared by the ray generation shader (outgoing, at the next location) and by each callable
  // shader (incoming, as `call`).
  const size_t location = out.payloads++, first = k.callables.size();
  Data payload;
  payload.set("display", display);
  payload.set("callName", callName);
  payload.set("returnType", retType);
  payload.set("returnsVoid", retType == "void");
  payload.set("location", std::to_string(location));
  payload.set("variable", variable);
  Data fields = List();
  for (unsigned i = 0; i < m->getNumParams(); ++i) {
    const ParmVarDecl* p = m->getParamDecl(i);
    Data x;
    x.set("declaration", kernelPrinter.Declare(PassedType(m, i), CallArgumentName(m, i), p->getLocation()));
    fields.push_back(x);
  }
  payload.set("fields", fields);
  payload.set("incoming", false);
  const std::string payloadTemplate = model.templateDir + "/glsl/callable_payload.glsl.mustache";
  out.structs.push_back({callName + "_Call", Render(payloadTemplate, payload)});
  payload.set("incoming", true);
  const std::string incomingPayload = Render(payloadTemplate, payload);

  std::string names;
  for (const VirtualImpl& vi : vm.impls) {
    auto impl = std::find_if(impls.begin(), impls.end(), [&](const CXXRecordDecl* r) { return r->getNameAsString() == vi.name; });
    const auto& [dataStruct, objectsReference] = implData.at(vi.name);
    AddCallableShader(ctx, rep, model, vm, vi, *impl, m, callLoc, dataStruct.text, objectsReference.text, incomingPayload);
    k.callables.push_back(vm.member + "_" + vi.name + "_" + method);
    names += (names.empty() ? "" : ", ") + k.callables.back();
  }
  // The dispatcher (templates/glsl/callable_dispatcher.glsl.mustache): the arguments into the
  // payload, the callable shader of the object's class, the written-back arguments and the result out.
  Data d;
  d.set("display", display);
  d.set("returnType", retType);
  d.set("returnsVoid", retType == "void");
  d.set("callName", callName);
  d.set("params", DispatcherParams(kernelPrinter, m, model.forIspc));
  d.set("member", vm.member);
  d.set("variable", variable);
  Data classes = List(), arguments = List();
  for (size_t t = 0; t < vm.impls.size(); ++t) {
    Data x;
    x.set("tag", std::to_string(t));
    x.set("class", vm.impls[t].name);
    classes.push_back(x);
  }
  for (unsigned i = 0; i < m->getNumParams(); ++i) {
    Data x;
    x.set("name", CallArgumentName(m, i));
    x.set("writtenBack", WrittenBack(m, i));
    arguments.push_back(x);
  }
  d.set("classes", classes);
  d.set("arguments", arguments);
  d.set("first", std::to_string(first));
  d.set("location", std::to_string(location));
  d.set("shaders", names);
  out.functions.push_back(Render(model.templateDir + "/glsl/callable_dispatcher.glsl.mustache", d));
}

}  // namespace

void VirtualCallCode(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, KernelPrinter& kernelPrinter, const VirtualOwner& owner,
                     std::vector<GlslDecl>& structs, std::vector<std::string>& functions, CallableCode* callable) {
  // Vectors and methods in source order: the generated code must not depend on where the AST
  // happens to sit in memory (the daemon reparses).
  SourceManager& sm = ctx.getSourceManager();
  auto before = [&](const Decl* a, const Decl* b) { return sm.isBeforeInTranslationUnit(a->getLocation(), b->getLocation()); };
  std::vector<std::pair<const FieldDecl*, std::vector<const CXXMethodDecl*>>> calls;
  for (auto& [field, method] : kernelPrinter.Uses().virtualCalls) {
    auto same = std::find_if(calls.begin(), calls.end(), [&, f = field](const auto& c) { return c.first == f; });
    if (same == calls.end()) same = calls.insert(calls.end(), {field, {}});
    same->second.push_back(method);
  }
  std::sort(calls.begin(), calls.end(), [&](const auto& a, const auto& b) { return before(a.first, b.first); });
  for (auto& c : calls) std::sort(c.second.begin(), c.second.end(), before);
  for (auto& [field, methods] : calls) {
    QualType element;
    IsStdVector(field->getType(), &element);
    const CXXRecordDecl* interface = PolymorphicPointee(element);
    const std::string member = owner.prefix + field->getNameAsString();
    if (owner.holder.empty()) RequireReachable(rep, field, owner.cls);
    else RequirePublicForComposition(rep, field, owner.cls->getNameAsString(), "");
    std::vector<const CXXRecordDecl*> impls;
    FindImplementations(ctx.getTranslationUnitDecl(), interface, impls);
    if (impls.empty()) {
      rep.GpuError(field->getLocation(), "kernels call " + interface->getNameAsString() + " through '" + member + "', but no class that implements it is defined here",
                  "define the implementations (classes derived from " + interface->getNameAsString() + ") in a header the class's source includes");
      continue;
    }
    auto known = std::find_if(model.virtuals.begin(), model.virtuals.end(), [&](const VirtualMember& v) { return v.member == member; });
    if (known == model.virtuals.end()) {
      VirtualMember vm;
      vm.member = member;
      vm.hostExpr = owner.hostPrefix + field->getNameAsString();
      vm.display = owner.holder.empty() ? member : owner.holder + "->" + field->getNameAsString();
      vm.interfaceName = interface->getNameAsString();
      vm.interfaceCpp = interface->getQualifiedNameAsString();
      for (auto* impl : impls) {
        VirtualImpl vi;
        vi.name = impl->getNameAsString();
        vi.cppName = impl->getQualifiedNameAsString();
        vi.header = FileOf(ctx, impl->getLocation());
        std::vector<const FieldDecl*> fields;
        CollectObjectFields(impl, fields);
        bool ok = true;
        for (auto* f : fields) {
          auto g = GlslTypeOf(f->getType());
          if (!g || f->getType()->isPointerType() || IsStdVector(f->getType()) || f->isBitField()) {
            rep.GpuError(f->getLocation(), "member '" + f->getNameAsString() + "' of " + vi.name + " cannot be copied to the GPU (kernels call " + vm.interfaceName +
                        " through '" + member + "')", "objects called through virtual functions hold plain data: scalars, LiteMath types and structs of them");
            ok = false;
            continue;
          }
          QualType base = f->getType();
          while (auto* arr = dyn_cast<ConstantArrayType>(base.getCanonicalType().getTypePtr())) base = arr->getElementType();
          std::string read = "from." + f->getNameAsString();
          if (f->getAccess() != AS_public) {  // private or protected: read through a member pointer
            const CXXRecordDecl* owner = cast<CXXRecordDecl>(f->getParent());
            HiddenField h{owner->getNameAsString() + "_" + f->getNameAsString(), owner->getQualifiedNameAsString(), f->getNameAsString(),
                          CppTypeName(ctx, f->getType().getCanonicalType())};
            read = "(from.*PointerTo(" + h.tag + "{}))";
            vi.hidden.push_back(h);
          }
          vi.fields.push_back({f->getNameAsString(), CppTypeName(ctx, base.getCanonicalType()), *g, 4, read, ""});
        }
        if (!ok) continue;
        auto cpp = MirrorOffsets(ctx, fields, 0), std430 = MirrorOffsets(ctx, fields, 1), scalar = MirrorOffsets(ctx, fields, 2);
        vi.size = unsigned(cpp->back());
        if (std430 && *std430 == *cpp) vi.scalarLayout = false;
        else if (scalar && *scalar == *cpp) vi.scalarLayout = true;
        else {
          rep.GpuError(impl->getLocation(), "the data of " + vi.name + " cannot be laid out on the GPU as C++ lays it out",
                      "use 32-bit scalars and LiteMath vectors; put 16-byte types (float4) first");
          continue;
        }
        vm.impls.push_back(vi);
      }
      if (model.virtualLevel == 1) {  // one slot size for all: the largest class's data, in 16-byte steps
        for (auto& vi : vm.impls) vm.slotBytes = std::max(vm.slotBytes, (vi.size + 15) / 16 * 16);
        for (auto& vi : vm.impls) vi.paddingWords = (vm.slotBytes - vi.size) / 4;
        // The GPU has one <Impl>_Data per class: vectors of two interfaces that share a class
        // must give it the same slot.
        for (auto& other : model.virtuals)
          for (auto& theirs : other.impls)
            for (auto& vi : vm.impls)
              if (theirs.name == vi.name && theirs.paddingWords != vi.paddingWords)
                rep.GpuError(field->getLocation(), "at virtual-function level 1, " + vi.name + " takes a " + std::to_string(vm.slotBytes) + "-byte slot in '" + member +
                          "' but a " + std::to_string(other.slotBytes) + "-byte slot in '" + other.member + "'",
                          "use level 2 (a buffer per class), where a class's objects need no slot");
      }
      for (auto& other : model.virtuals) vm.firstClassConstant += unsigned(other.impls.size());
      model.virtuals.push_back(vm);
      known = model.virtuals.end() - 1;
    }
    const VirtualMember& vm = *known;
    const bool ispc = model.forIspc;  // ISPC: the class data points at the tags and at each class's objects
    if (!ispc) {
      k.bufferReferences = true;
      // Data structs and buffer references, then each implementation's methods.
      const GlslDecl tags = TagsReference(model, vm);
      structs.push_back(tags);
      for (auto& c : ClassConstants(model, vm)) structs.push_back(c);
      if (callable) callable->structs.push_back(tags);
    }
    std::map<std::string, std::string> implFunction;  // (impl, method) -> GLSL name
    std::map<std::string, std::pair<GlslDecl, GlslDecl>> implData;  // impl -> (data struct, buffer reference to its objects)
    for (auto* impl : impls) {
      auto vi = std::find_if(vm.impls.begin(), vm.impls.end(), [&](const VirtualImpl& x) { return x.name == impl->getNameAsString(); });
      if (vi == vm.impls.end()) continue;
      std::unique_ptr<KernelPrinter> implPrinter = MakePrinter(model, ctx, impl, rep);
      KernelPrinter& printer = *implPrinter;
      printer.selfClass = impl;
      printer.composedPrefix = vi->name + "_";
      printer.owner = &kernelPrinter;  // what the methods read through a pointer to the caller
      for (auto& sn : ClassStructNames(model)) printer.predeclaredStructs.insert(sn);
      const GlslDecl data = ImplDataStruct(model, printer, impl, vm, *vi);
      for (auto* m : methods) implFunction[vi->name + "::" + m->getNameAsString()] = ImplementationMethod(rep, printer, impl, m, field->getLocation());
      for (auto& x : printer.Structs()) structs.push_back(x);
      structs.push_back(data);
      if (!ispc) {
        const GlslDecl objectsReference = ObjectsReference(model, vm, *vi);
        structs.push_back(objectsReference);
        implData[vi->name] = {data, objectsReference};
        k.scalarReferences |= vi->scalarLayout;
      }
      for (auto& x : printer.Constants())
        if (std::find(k.constantList.begin(), k.constantList.end(), x) == k.constantList.end()) k.constantList.push_back(x);
      for (auto& x : printer.Functions()) functions.push_back(x);
    }
    for (auto* m : methods) {
      // The dispatcher (templates/glsl/dispatcher.glsl.mustache): a case per implementing class.
      auto ret = kernelPrinter.Type(m->getReturnType(), m->getLocation());
      const std::string retType = ret ? *ret : "void";
      Data d;
      d.set("display", vm.display);
      d.set("method", m->getNameAsString());
      d.set("argsHint", m->getNumParams() ? "(...)" : "()");
      d.set("returnType", retType);
      d.set("returnsVoid", retType == "void");
      d.set("member", member);
      d.set("params", DispatcherParams(kernelPrinter, m, model.forIspc));
      d.set("dataStruct", kernelPrinter.DataStruct());
      Data cases = List();
      for (size_t t = 0; t < vm.impls.size(); ++t) {
        const auto& vi = vm.impls[t];
        // Level 1: all elements in one array of equal slots; level 2: each class's objects apart.
        // (ISPC, at every level: an array per class that the class data points at.)
        const std::string address = model.virtualLevel == 1 ? generated::VirtualSlotsField(member) : generated::VirtualClassField(member, vi.name);
        std::string args = ispc ? "self->" + generated::VirtualClassField(member, vi.name) + "[slot]" : member + "_" + vi.name + "Objects(" + address + ").objects[tag.y]";
        for (unsigned i = 0; i < m->getNumParams(); ++i)  // the caller itself: GLSL leaves it out, ISPC passes the class data
          if (!KernelPrinter::PointsTo(m->getParamDecl(i)->getType(), kernelPrinter.Class())) args += ", " + CallArgumentName(m, i);
          else if (ispc) args += ", self";
        Data x;
        x.set("tag", std::to_string(t));
        x.set("call", implFunction[vi.name + "::" + m->getNameAsString()] + "(" + args + ")");
        x.set("returnsVoid", retType == "void");
        x.set("held", ispc ? "" : ClassConstantName(vm, t));
        x.set("class", vi.name);
        cases.push_back(x);
      }
      d.set("cases", cases);
      functions.push_back(Render(model.templateDir + (ispc ? "/ispc/dispatcher.ispc.mustache" : "/glsl/dispatcher.glsl.mustache"), d));
      if (callable && !ispc) CallableDispatcher(ctx, rep, model, k, kernelPrinter, vm, impls, m, field->getLocation(), implData, *callable);
    }
  }
}

}  // namespace crossrt::engine
