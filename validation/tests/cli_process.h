// The `warpcheck` executable as a process, for the tests that specify its command line: where it is, starting
// it with its output in files, its exit status, a file's text.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern char** environ;

namespace warpcheck::test {

// The CLI is built into the build root; the test executable runs from build/validation/ or the build root.
inline std::filesystem::path warpcheck_cli() {
  std::filesystem::path dir = std::filesystem::read_symlink("/proc/self/exe").parent_path();
  if (!std::filesystem::exists(dir / "warpcheck")) dir = dir.parent_path();
  return dir / "warpcheck";
}

// Starts the CLI with args, stdout and stderr to dir/name.out and dir/name.err; returns its pid (-1 on failure).
inline pid_t start(const std::vector<std::string>& args, const std::filesystem::path& dir, const std::string& name) {
  std::vector<std::string> all = {warpcheck_cli().string()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, (dir / (name + ".out")).c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, (dir / (name + ".err")).c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  return rc == 0 ? pid : -1;
}

// Waits for pid; its exit status, or 128 + the signal that ended it.
inline int exit_status(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

inline std::string read_all(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

}  // namespace warpcheck::test
