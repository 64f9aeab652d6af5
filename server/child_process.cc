#include "server/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace zebrageo {

pid_t StartChild(const ChildSpec& spec) {
  // Everything the child needs is prepared before fork: between fork and
  // exec a child of a threaded process may only make async-signal-safe
  // calls.
  std::vector<std::string> strings = {spec.executable};
  strings.insert(strings.end(), spec.args.begin(), spec.args.end());
  std::vector<char*> argv;
  for (std::string& s : strings) argv.push_back(s.data());
  argv.push_back(nullptr);
  const int log = open(spec.log_path.c_str(),
                       O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log < 0) {
    throw std::runtime_error(spec.log_path + ": " + std::strerror(errno));
  }
  const int null_in = open("/dev/null", O_RDONLY | O_CLOEXEC);
  const pid_t parent = getpid();
  rlimit memory{};
  memory.rlim_cur = memory.rlim_max = static_cast<rlim_t>(spec.memory_limit_mb)
                                      << 20;

  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the server died meanwhile
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGPIPE, SIG_DFL);
    if (null_in >= 0) dup2(null_in, 0);
    dup2(log, 1);
    dup2(log, 2);
    syscall(SYS_close_range, 3U, ~0U, 0U);
    if (spec.memory_limit_mb > 0) setrlimit(RLIMIT_AS, &memory);
    execv(argv[0], argv.data());
    static const char kMessage[] = "zebrageo: error: cannot execute worker\n";
    (void)!write(2, kMessage, sizeof(kMessage) - 1);
    _exit(127);
  }
  const int fork_errno = errno;
  close(log);
  if (null_in >= 0) close(null_in);
  if (pid < 0) {
    throw std::runtime_error(std::string("fork: ") + std::strerror(fork_errno));
  }
  // Also from the parent: a signal sent before the child ran setpgid must
  // still reach its group.
  setpgid(pid, pid);
  return pid;
}

std::optional<ChildExit> PollChild(pid_t pid) {
  int status = 0;
  const pid_t got = waitpid(pid, &status, WNOHANG);
  if (got == 0) return std::nullopt;
  ChildExit exit;
  if (got < 0) return exit;  // not our child any more: treat as gone
  if (WIFEXITED(status)) {
    exit.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    exit.signal = WTERMSIG(status);
  }
  return exit;
}

void SignalChild(pid_t pid, int signal) {
  if (pid <= 0) return;
  if (kill(-pid, signal) != 0) kill(pid, signal);
}

std::string SelfExecutable() {
  std::error_code error;
  const auto path = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) throw std::runtime_error("/proc/self/exe: " + error.message());
  return path.string();
}

bool ProcessRunsWith(long pid, const std::string& needle) {
  if (pid <= 0) return false;
  std::ifstream in("/proc/" + std::to_string(pid) + "/cmdline",
                   std::ios::binary);
  if (!in) return false;
  std::ostringstream text;
  text << in.rdbuf();
  std::string command = text.str();
  for (char& c : command) {
    if (c == '\0') c = ' ';
  }
  return command.find(needle) != std::string::npos;
}

}  // namespace zebrageo
