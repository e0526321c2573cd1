#pragma once

// Test helper: a private X server (Xvfb, Mesa's llvmpipe renders into it) started by the
// test and stopped by its PID; DISPLAY points at it while it lives.

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

namespace tessera::gui::testing {

class Xvfb {
 public:
  // False with the reason when Xvfb is missing or does not come up within 10 s.
  bool Start(std::string* why) {
    int fds[2];
    if (pipe(fds) != 0) {
      *why = "pipe() failed";
      return false;
    }
    pid_ = fork();
    if (pid_ == 0) {
      close(fds[0]);
      const std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1600x1000x24", "-nolisten",
             "tcp", "-noreset", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    std::string number;
    pollfd poll_fd{fds[0], POLLIN, 0};
    while (poll(&poll_fd, 1, 10000) > 0) {
      char c = 0;
      if (read(fds[0], &c, 1) != 1 || c == '\n') break;
      number += c;
    }
    close(fds[0]);
    if (number.empty()) {
      *why = "Xvfb is not installed or did not start (apt-get install xvfb)";
      Stop();
      return false;
    }
    setenv("DISPLAY", (":" + number).c_str(), 1);
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);  // llvmpipe: the same pixels everywhere
    return true;
  }
  void Stop() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  ~Xvfb() { Stop(); }

 private:
  pid_t pid_ = -1;
};

}  // namespace tessera::gui::testing
