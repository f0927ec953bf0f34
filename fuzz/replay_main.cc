// The harnesses without libFuzzer (the gcc build's ctest fuzz_smoke_<reader>): every file of
// the seed corpora given as arguments, then deterministic mutations of each (truncations, byte
// flips and insertions from a fixed seed), so that CI exercises the hostile-input paths in
// seconds. A finding aborts, as under libFuzzer.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

// MBID_FUZZ_LAST_INPUT=<file>: each input is written there before it runs, so that the input of
// a crash is left behind to become a regression test.
void Run(const std::vector<uint8_t>& bytes) {
  static const char* keep = std::getenv("MBID_FUZZ_LAST_INPUT");
  if (keep != nullptr && *keep != '\0') {
    std::ofstream(keep, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
  LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
}

std::vector<uint8_t> ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path given(argv[i]);
    if (std::filesystem::is_directory(given)) {
      for (const auto& entry : std::filesystem::directory_iterator(given)) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
    } else {
      files.push_back(given);
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "usage: %s <corpus file or folder>...\n", argv[0]);
    return 2;
  }
  std::mt19937 random(17);  // fixed: the same inputs on every run
  long long runs = 0;
  for (const auto& file : files) {
    const std::vector<uint8_t> seed = ReadFile(file);
    Run(seed);
    ++runs;
    for (const size_t keep : {seed.size() / 4, seed.size() / 2, seed.size() * 3 / 4,
                              seed.size() > 0 ? seed.size() - 1 : 0}) {
      Run(std::vector<uint8_t>(seed.begin(), seed.begin() + static_cast<std::ptrdiff_t>(keep)));
      ++runs;
    }
    if (seed.empty()) continue;
    for (int m = 0; m < 48; ++m) {
      std::vector<uint8_t> mutated = seed;
      const int edits = 1 + m % 4;
      for (int e = 0; e < edits; ++e) {
        const size_t at = random() % mutated.size();
        switch (random() % 4) {
          case 0:  // flip bits
            mutated[at] ^= static_cast<uint8_t>(1 + random() % 255);
            break;
          case 1:  // an interesting byte: 0, 0xFF, a non-UTF-8 lead byte, a separator
            mutated[at] = std::vector<uint8_t>{0x00, 0xFF, 0xC3, 0x80, ',', '\n'}[random() % 6];
            break;
          case 2: {  // duplicate a stretch (copied first: insert may reallocate)
            const std::vector<uint8_t> stretch(
                mutated.begin() + static_cast<std::ptrdiff_t>(at),
                mutated.begin() + static_cast<std::ptrdiff_t>(std::min(mutated.size(), at + 16)));
            mutated.insert(mutated.begin() + static_cast<std::ptrdiff_t>(at), stretch.begin(),
                           stretch.end());
            break;
          }
          default:  // delete a stretch
            mutated.erase(
                mutated.begin() + static_cast<std::ptrdiff_t>(at),
                mutated.begin() + static_cast<std::ptrdiff_t>(std::min(mutated.size(), at + 8)));
            if (mutated.empty()) mutated.push_back('0');
            break;
        }
      }
      Run(mutated);
      ++runs;
    }
  }
  std::printf("%lld inputs from %zu seed files: no finding\n", runs, files.size());
  return 0;
}
