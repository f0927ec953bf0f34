#pragma once

// What every harness shares: the input as a file where the reader needs a path, and the rule
// that a reader may refuse input only with mbid's documented errors (exit 2, or 3 for a
// numerical failure); any other exception, a crash or a hang is a finding.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "mbid/common/error.h"

namespace mbid::fuzz {

// A folder of this process, removed when the process ends normally (a crash leaves it, with
// the input that crashed it).
class ScratchFolder {
 public:
  ScratchFolder()
      : path_(std::filesystem::temp_directory_path() /
              ("mbid-fuzz-" + std::to_string(static_cast<long long>(getpid())))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// `data` written to a file with the given extension (readers choose the format by it), in a
// folder of this process so that parallel fuzzers do not share it.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& extension) {
  static const ScratchFolder folder;
  const std::string path = (folder.path() / ("input" + extension)).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

// Runs `read`; returns normally for mbid's documented errors and aborts (a finding) otherwise.
template <typename Read>
void ExpectContractErrorsOnly(Read&& read) {
  try {
    read();
  } catch (const InputError&) {        // exit 2
  } catch (const NumericalError&) {    // exit 3
  } catch (const std::exception& e) {  // exit 1: not a documented answer to a bad file
    std::fprintf(stderr, "fuzz: exception outside the contract (exit 1): %s\n", e.what());
    std::abort();
  }
}

}  // namespace mbid::fuzz
