// ISPC loads of whole structs from member vectors. Rays in neighbouring SIMD lanes mostly ask for the
// same element (a BVH node near the root, the one instance of a scene), and a gather of a 128-byte
// node is 32 gathers. So an element of 32 bytes or more, read whole at an index that differs per lane,
// goes through a helper that loads each value the lanes agree on once, for up to four such values,
// and gathers for the lanes left. The helper reads what the gather reads: the result is the same.
// Only a const element qualifies (read in a const method: nothing writes through it), and only one
// read whole, not the base of a field access (m_triangles[g].coord[k] reads 16 of 144 bytes).
// Part of GlslPrinter (Glsl.h).
#include "AstQueries.h"
#include "Glsl.h"
#include "GlslParts.h"
#include "GlslTypes.h"

#include <algorithm>
#include <sstream>

using namespace clang;

namespace crossrt::engine {

namespace {

constexpr int64_t kCoherentLoadBytes = 32;  // below this a gather is as cheap as the test
constexpr int kAgreedValues = 4;             // values loaded once before the rest gather

}  // namespace

std::string GlslPrinter::IspcCoherentLoad(const clang::CXXOperatorCallExpr* op) {
  if (!ispc || op->getOperator() != OO_Subscript || op == m_fieldBase) return "";
  const FieldDecl* field = ThisMemberField(op->getArg(0));
  const QualType element = op->getType().getCanonicalType();
  if (!field || !IsStdVector(field->getType()) || !element.isConstQualified() || !element->isRecordType() ||
      element->isIncompleteType() || m_ctx.getTypeSizeInChars(element).getQuantity() < kCoherentLoadBytes || IspcUniform(op->getArg(1)))
    return "";
  const auto glsl = GlslTypeOf(element.getUnqualifiedType());
  if (!glsl) return "";
  const std::string type = IspcTypeName(*glsl), helper = "crt_load_" + type;
  if (!std::count(m_coherentLoads.begin(), m_coherentLoads.end(), type)) {
    m_coherentLoads.push_back(type);
    std::ostringstream os;
    os << "// a[i], a " << type << " for each lane: one load for each index the lanes agree on (up to " << kAgreedValues
       << "), a gather for the rest\n"
       << "static inline " << type << " " << helper << "(const uniform " << type << " *uniform a, uint i)\n{\n"
       << "  " << type << " e;\n"
       << "  bool pending = true;\n"
       << "  for (uniform int k = 0; k < " << kAgreedValues << "; ++k)\n  {\n"
       << "    if (!any(pending))\n      return e;\n"
       << "    const uniform uint agreed = extract(i, count_trailing_zeros(lanemask() & packmask(pending)));\n"
       << "    if (i == agreed)\n    {\n      e = a[agreed];\n      pending = false;\n    }\n  }\n"
       << "  if (pending)\n    e = a[i];\n"
       << "  return e;\n}\n";
    m_functions.push_back(os.str());
  }
  return helper + "(" + Expr(op->getArg(0)) + ", (uint)(" + Expr(op->getArg(1)) + "))";
}

}  // namespace crossrt::engine
