// The CPU class's copies of the user's code: declarations and macros a kernel's body needs copied
// next to it, and the helpers that push_back to member vectors rewritten to take a lock (AddLockedCopies).
#pragma once
#include "analyse/AnalysisContext.h"

namespace crossrt::engine {

void CopySourceDeclarations(Context& c, const Stmt* body, const std::string& what);

// `v.push_back(x)` -> `crossrt::Locked(v).push_back(x)` for the class's member vectors in `body`.
void LockAppends(Rewriter& rw, const Stmt* body);

// The member functions a kernel's threads run that append, themselves or through calls: the CPU
// backend gets copies of them whose appends take a lock (see LockedCopy).
void AddLockedCopies(Context& c, const std::vector<const FunctionDecl*>& reached);

}  // namespace crossrt::engine
