// The name of an HDF5 output (-o): one that says another record format is refused, so that no
// HDF5 file ends up named .csv or .mat, which mbid itself would then read as that format.
#include "mbid/app/commands.h"
#include "mbid/common/error.h"
#include "mbid/records/records.h"

namespace mbid::app {

void CheckHdf5OutputName(const std::string& path) {
  if (path.empty() || path == "-") return;
  const std::string extension = records::LowerExtension(path);
  if (extension == ".h5" || extension == ".hdf5" || !records::IsSupportedFile(path)) return;
  throw InputError("-o", path,
                   "'" + extension + "' names another record format, and -o writes HDF5",
                   "a .h5 file name (mbid simulate --export writes .csv, .uff, .uffb and .mat)");
}

}  // namespace mbid::app
