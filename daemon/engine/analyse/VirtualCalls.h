// Virtual calls through std::vector<Interface*> members (paper 3.9): finds the implementations of the
// interface, lays out each one's data as the GPU mirrors it, and records the calls a kernel makes.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// Classes of the translation unit (outside system headers) that implement `interface`: concrete
// and derived from it, in declaration order.
void FindImplementations(const DeclContext* dc, const CXXRecordDecl* interface, std::vector<const CXXRecordDecl*>& out);

// The data of an object, base classes first, as the GPU mirror holds it.
void CollectObjectFields(const CXXRecordDecl* rd, std::vector<const FieldDecl*>& out);

// Offsets of a struct with these fields, in order, laid out by C++ (natural alignment) or by a GLSL
// layout; nullopt when a field has no GLSL layout.
std::optional<std::vector<uint64_t>> MirrorOffsets(ASTContext& ctx, const std::vector<const FieldDecl*>& fields, int layout /* 0 C++, 1 std430, 2 scalar */);

// The implementation of `method` the GPU runs for objects of `impl`: its GLSL name, or "" (reported).
std::string ImplementationMethod(Reporter& rep, KernelPrinter& printer, const CXXRecordDecl* impl, const CXXMethodDecl* method, SourceLocation callLoc);

// The generated class derives from `cls` and names member `f`: a private one is an error.
void RequireReachable(Reporter& rep, const FieldDecl* f, const CXXRecordDecl* cls);

// The generated class reaches member `f` of a composed implementation through an `implName`*: a
// member the GPU reads must be public. `how` names the composition, "" or " (IScene=ShapeScene)".
void RequirePublicForComposition(Reporter& rep, const FieldDecl* f, const std::string& implName, const std::string& how);

// The GLSL name of a virtual method's parameter i: the interface's (it may leave it unnamed).
std::string CallArgumentName(const CXXMethodDecl* m, unsigned i);

// A non-const reference parameter of a virtual method, or a pointer to a non-const value: its value
// comes back to the caller.
bool WrittenBack(const CXXMethodDecl* m, unsigned i);
// The type of the value a dispatcher passes for parameter i: a reference's or a pointer's pointee
// (a virtual method's pointer parameter is the one value the caller's &x points at).
QualType PassedType(const CXXMethodDecl* m, unsigned i);

// ", vec3 normal, inout float weight": a dispatcher's parameters after the element's index.
std::string DispatcherParams(KernelPrinter& printer, const CXXMethodDecl* m, bool forIspc);

// The specialization constants that say which classes a vector's objects hold (kClassConstantIdBase),
// one per class: a dispatcher's case for a class the scene lacks is dead code in the pipeline.
std::vector<GlslDecl> ClassConstants(const ClassModel& model, const VirtualMember& vm);
std::string ClassConstantName(const VirtualMember& vm, size_t t);  // crt_m_materials_holdsLambert

// The buffer reference to a vector's tags: per element, its class and where its object is.
GlslDecl TagsReference(const ClassModel& model, const VirtualMember& vm);

// The GLSL mirror of the data of an implementation's objects (printed by its object-mode printer).
GlslDecl ImplDataStruct(const ClassModel& model, KernelPrinter& printer, const CXXRecordDecl* impl, const VirtualMember& vm, const VirtualImpl& vi);

// The buffer reference to the objects of one implementation (level 2 and 3).
GlslDecl ObjectsReference(const ClassModel& model, const VirtualMember& vm, const VirtualImpl& vi);

// The size of a vector of objects is in the class data next to the vector's tags, which exist for
// vectors the kernel calls through.
void CheckObjectSizeReads(Reporter& rep, const KernelPrinter& printer);

// The kernel's own code calls virtual functions through the class's vectors of objects.
void AnalyzeVirtualCalls(Context& c, Kernel& k, KernelPrinter& kernelPrinter);

// Where the vectors of objects that code calls virtual functions through live: the translated
// class (its own members), or a composed implementation (the code of listing 2 of the paper: a
// traversal calling an intersection function per primitive), whose members the generated class
// reaches through the holder and whose GLSL names carry the holder's prefix.
struct VirtualOwner {
  const CXXRecordDecl* cls;  // the class declaring the vectors
  std::string prefix;        // "" or "m_scene_"
  std::string hostPrefix;    // "" or "crt_m_scene()->"
  std::string holder;        // "" or "m_scene"
};

}  // namespace crossrt::engine
