// Runs the built sdfstream binary for the CLI tests: exit code, stdout and stderr (or both in
// `out` when mergeStderr), so every test checks the same way that errors are one line and
// outputs appear.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace sdfstream::test {

struct CliResult {
  int exitCode = -1;
  std::string out;
  std::string err;  // empty when merged into out
};

inline CliResult runCli(const std::string& binary, const std::string& arguments,
                        bool mergeStderr = false) {
  namespace fs = std::filesystem;
  static int counter = 0;
  const fs::path errFile =
      fs::temp_directory_path() /
      ("sdfstream-cli-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  const std::string cmd =
      binary + " " + arguments + (mergeStderr ? std::string(" 2>&1") : " 2>" + errFile.string());
  CliResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf;
  while (std::size_t n = fread(buf.data(), 1, buf.size(), pipe)) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (!mergeStderr) {
    std::ifstream e(errFile);
    r.err.assign(std::istreambuf_iterator<char>(e), {});
    fs::remove(errFile);
  }
  return r;
}

inline std::string readText(const std::filesystem::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace sdfstream::test
