// The code of virtual calls: per implementation its data struct and methods printed with `self`, per
// method a dispatcher that switches over the object's class (levels 1-2), or at level 3 a callable
// shader per implementation and the call that the ray generation shader makes.
#pragma once
#include "analyse/AnalysisContext.h"
#include "analyse/VirtualCalls.h"

namespace crossrt::engine {

// Level 3: what a kernel's ray generation shader has instead of the switches.
struct CallableCode {
  std::vector<GlslDecl> structs;       // the vectors' tags, the calls' payloads and the variables passed to executeCallableEXT
  std::vector<std::string> functions;  // per method, a dispatcher that executes the callable shader of the object's class
  unsigned payloads = 0;               // callableDataEXT variables so far: the next one's location
};

// Code calls `m_objects[i]->Method(...)`: for every implementation of the interface, its data as
// a GLSL struct in a buffer of its own (reached by a buffer reference), its methods printed with
// `self`, and per method a dispatcher that switches over the object's class. The structs and
// functions to put ahead of the calling code go to `structs` and `functions`; at level 3, with
// `callable` given, also the callable shaders of the implementations and what the ray generation
// shader calls them with.
void VirtualCallCode(ASTContext& ctx, Reporter& rep, ClassModel& model, Kernel& k, KernelPrinter& kernelPrinter, const VirtualOwner& owner,
                     std::vector<GlslDecl>& structs, std::vector<std::string>& functions, CallableCode* callable = nullptr);

}  // namespace crossrt::engine
