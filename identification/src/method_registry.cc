#include "methods/method.h"

namespace mbid::identification {

// One declaration and one entry per method; its file is methods/<name>.cc.
MethodDefinition HankelNlsMethod();
MethodDefinition PronySvdMethod();

const std::vector<MethodDefinition>& MethodRegistry() {
  static const std::vector<MethodDefinition> methods{HankelNlsMethod(), PronySvdMethod()};
  return methods;
}

const MethodDefinition* FindMethod(const std::string& name) {
  for (const MethodDefinition& method : MethodRegistry()) {
    if (name == method.name) return &method;
  }
  return nullptr;
}

std::vector<std::string> MethodNames() {
  std::vector<std::string> names;
  for (const MethodDefinition& method : MethodRegistry()) names.push_back(method.name);
  return names;
}

std::string MethodName(const Method& method) { return method.name(); }

bool ParseMethod(const std::string& name, Method* method) {
  if (FindMethod(name) == nullptr) return false;
  *method = Method(name);
  return true;
}

}  // namespace mbid::identification
