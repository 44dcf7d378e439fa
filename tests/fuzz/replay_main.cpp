// SPDX-License-Identifier: BSD-3-Clause
// Runs one fuzz target's LLVMFuzzerTestOneInput on files, without libFuzzer: the seed corpus
// and every regression input (a crash, hang or sanitizer report found once) in the ordinary
// test suite, under whatever compiler and sanitizers it is built with (docs/developers/fuzzing.md).
// Arguments: [--all-accepted] files or folders (every regular file in them, in name order);
// with --all-accepted (the seed corpora) an input refused with an InputError fails the run:
// a seed that never reaches past the reader fuzzes nothing.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  bool allAccepted = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--all-accepted") {
      allAccepted = true;
      continue;
    }
    const std::filesystem::path path = argv[i];
    if (std::filesystem::is_directory(path)) {
      for (const auto& entry : std::filesystem::directory_iterator(path))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else if (std::filesystem::is_regular_file(path)) {
      files.push_back(path);
    } else {
      std::cerr << path.string() << ": no such file or folder\n";
      return 2;
    }
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::cerr << "no input given\n";
    return 2;
  }
  for (const auto& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::cout << file.filename().string() << "\n" << std::flush;  // the last name printed is the culprit of a crash
    const int before = mcopt::fuzz::refusalCount();
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    if (mcopt::fuzz::refusalCount() > before) {
      std::cout << "  refused: " << mcopt::fuzz::lastRefusal() << "\n";
      if (allAccepted) {
        std::cerr << file.string() << ": a seed input was refused\n";
        return 1;
      }
    }
  }
  std::cout << files.size() << " inputs ran, " << mcopt::fuzz::refusalCount() << " refused\n";
  return 0;
}
