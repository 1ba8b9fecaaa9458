// A child process for the rostest nodes that start programs themselves
// (Xvfb, rviz, the node with bad parameters).
#pragma once

#include <csignal>
#include <cstdlib>
#include <fcntl.h>
#include <optional>
#include <spawn.h>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace stc_test {

// A child process killed (SIGINT, then SIGKILL) when it goes out of scope.
class Child {
 public:
  // Output goes to `output_file` when given (stdout and stderr), else is inherited.
  Child(std::vector<std::string> argv, const std::vector<std::string>& extra_env,
        const std::string& output_file = "") {
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    std::vector<std::string> env_strings(extra_env);
    for (char** e = environ; *e != nullptr; ++e) env_strings.emplace_back(*e);  // extra first: they win
    std::vector<char*> env;
    for (auto& e : env_strings) env.push_back(e.data());
    env.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (!output_file.empty()) {
      posix_spawn_file_actions_addopen(&actions, 1, output_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      posix_spawn_file_actions_adddup2(&actions, 1, 2);
    }
    spawn_error_ = posix_spawnp(&pid_, args[0], &actions, nullptr, args.data(), env.data());
    if (spawn_error_ != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (pid_ <= 0 || !running()) return;
    kill(pid_, SIGINT);
    for (int i = 0; i < 30; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      usleep(100000);
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  // False when the program could not be started (spawnError() says why).
  bool started() const { return pid_ > 0; }
  int spawnError() const { return spawn_error_; }
  bool running() {
    if (pid_ <= 0 || exit_status_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return false;
  }
  // Exit status once it has ended (128 + signal when killed).
  std::optional<int> exitStatus() {
    running();
    return exit_status_;
  }

 private:
  pid_t pid_ = -1;
  int spawn_error_ = 0;
  std::optional<int> exit_status_;
};

}  // namespace stc_test
