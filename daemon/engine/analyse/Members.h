// The class's data members: which become buffers (std::vector), class data, images, samplers,
// textures or vectors of objects, with their C++ and GLSL types. Takes the class; fills model.members
// and model.constructors.
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

// A single member of the class-data block: the C++ mirror declares it with alignas(std430
// alignment), so a lone float3 matches; float3x3 and bool do not. Arrays of float3 are held as
// arrays of float4 (IsArrayOf3Vectors).
bool FitsClassData(ASTContext& ctx, QualType t);
// A one-dimensional array of LiteMath 3-vectors (float3 coefs[9]): 12 bytes an element in C++, 16
// in std430. The class data holds it as 4-vectors, copied element by element.
bool IsArrayOf3Vectors(QualType t);

// A CRT_SPECIALIZE member's type is one a specialization constant can hold (else an error at it).
bool CheckSpecialized(Reporter& rep, const FieldDecl* f);

// The pass: every data member of the class (bases first) into model.members; constructors too.
void AnalyzeMembers(Context& c);

// The structs the class-wide prelude declares (the class data block needs them): other printers
// do not declare them again.
std::set<std::string> ClassStructNames(const ClassModel& model);

}  // namespace crossrt::engine
