#pragma once
// Runs the cdcr executable the way a user's shell does and returns its exit
// code, standard output and standard error. The including test target
// defines CDCR_CLI_PATH (the executable's path).

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#ifndef CDCR_CLI_PATH
#error "CDCR_CLI_PATH must name the cdcr executable"
#endif

namespace cdcr::test_support {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// `arguments` is shell text: quote paths that may hold spaces.
inline CliRun run_cdcr(const std::string& arguments) {
  static int run_count = 0;
  const std::string err_path =
      testing::TempDir() + "cdcr_stderr_" + std::to_string(getpid()) + "_" + std::to_string(run_count++);
  const std::string command = "'" CDCR_CLI_PATH "' " + arguments + " 2>'" + err_path + "'";
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t count = 0;
  while ((count = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), count);
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err_file(err_path);
  run.err.assign(std::istreambuf_iterator<char>(err_file), std::istreambuf_iterator<char>());
  std::remove(err_path.c_str());
  return run;
}

}  // namespace cdcr::test_support
