#pragma once
// A whole file as a string, for tests that check what a program wrote.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace varslam::test {

// The file's bytes ("" when it cannot be opened: the test's own assertion then names what is missing).
inline std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace varslam::test
