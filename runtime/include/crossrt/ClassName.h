// The name of an object's dynamic class, as the user wrote it: what generated classes say when a
// composed member holds an object of another class than the one composed into their kernels.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>
#include <typeinfo>
#if defined(__GNUC__)
#include <cxxabi.h>
#endif

namespace crossrt {

inline std::string ClassName(const std::type_info& type) {
#if defined(__GNUC__)
  int status = 0;
  std::unique_ptr<char, void (*)(void*)> name(abi::__cxa_demangle(type.name(), nullptr, nullptr, &status), std::free);
  if (status == 0 && name) return name.get();
#endif
  return type.name();
}

}  // namespace crossrt
