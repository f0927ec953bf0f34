#include "hdf5_internal.h"

namespace mbid::internal {
namespace {

herr_t CollectInnermost(unsigned n, const H5E_error2_t* error, void* data) {
  if (n == 0 && error->desc != nullptr) *static_cast<std::string*>(data) = error->desc;
  return 0;
}

}  // namespace

std::recursive_mutex& H5Mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}

void Check(herr_t status, const char* what) {
  if (status < 0) throw H5::Exception(what, "failed");
}

H5::DSetMemXferPropList SizedTransfer(hsize_t elements) {
  // 64 bytes per value covers every type read or written here (at most a 16-byte
  // variable-length descriptor on either side).
  constexpr size_t kBytesPerValue = 64;
  H5::DSetMemXferPropList transfer;
  transfer.setBuffer(static_cast<size_t>(std::max<hsize_t>(elements, 1)) * kBytesPerValue, nullptr,
                     nullptr);
  return transfer;
}

std::string Describe(const H5::Exception& e) {
  std::string innermost;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, CollectInnermost, &innermost);
  H5Eclear2(H5E_DEFAULT);
  std::string text =
      e.getFuncName().empty() ? e.getDetailMsg() : e.getFuncName() + ": " + e.getDetailMsg();
  if (!innermost.empty()) text += " (" + innermost + ")";
  return text;
}

std::string JoinPath(const std::string& group, const std::string& name) {
  if (group.empty() || group == "/") return "/" + name;
  return group.back() == '/' ? group + name : group + "/" + name;
}

std::string AttributeField(const std::string& object, const std::string& name) {
  return object + " attribute '" + name + "'";
}

std::vector<std::string> PathPrefixes(const std::string& path) {
  std::vector<std::string> prefixes;
  std::string current;
  size_t start = 0;
  while (start < path.size()) {
    size_t end = path.find('/', start);
    if (end == std::string::npos) end = path.size();
    if (end > start) {
      current += "/" + path.substr(start, end - start);
      prefixes.push_back(current);
    }
    start = end + 1;
  }
  return prefixes;
}

bool ObjectExists(const H5::H5File& file, const std::string& path) {
  const std::vector<std::string> prefixes = PathPrefixes(path);
  if (prefixes.empty()) return true;  // the root
  for (size_t i = 0; i < prefixes.size(); ++i) {
    if (!file.nameExists(prefixes[i])) return false;
    if (i + 1 < prefixes.size() && file.childObjType(prefixes[i]) != H5O_TYPE_GROUP) return false;
  }
  return true;
}

H5O_type_t ObjectType(const H5::H5File& file, const std::string& path) {
  if (PathPrefixes(path).empty()) return H5O_TYPE_GROUP;
  return file.childObjType(path);
}

H5::StrType VariableUtf8() {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

}  // namespace mbid::internal
