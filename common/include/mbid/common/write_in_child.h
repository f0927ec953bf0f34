#pragma once

#include <functional>
#include <string>

namespace mbid {

// Runs `write` (HDF5 writing `path` on disk) in a forked child process. HDF5 1.10.8 does not
// survive a write the file system refuses (full, or over the file-size limit): its object copy
// crashes on the error path (SIGSEGV in H5T_close_real, seen under H5Ocopy). In a child, such a
// crash is a failure the parent reports: std::runtime_error "cannot write <path>: ...", with the
// child's own error message when it threw. Where no child can be made (or MBID_NO_CHILD_PROBE is
// set, to debug in-process), `write` runs in this process. Holds H5Writer's process-wide HDF5
// lock throughout: other threads' HDF5 calls wait.
void WriteInChild(const std::string& path, const std::function<void()>& write);

}  // namespace mbid
