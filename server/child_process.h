// A job's `zebrageo run` as a child process: fork and exec of the zebrageo
// binary itself with an argument vector (no shell), so a survey that
// crashes or exhausts its worker fails alone.
//
// The child gets its own process group (a cancel signals the group), its
// stdout and stderr appended to the job's log, stdin from /dev/null, no
// file descriptor of the server's (sockets, the database), an empty signal
// mask, and PR_SET_PDEATHSIG: when the server dies, even by SIGKILL, its
// children die with it, so a restarted server never races an orphan for
// a results folder (it resumes the job itself).
#ifndef ZEBRAGEO_SERVER_CHILD_PROCESS_H_
#define ZEBRAGEO_SERVER_CHILD_PROCESS_H_

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace zebrageo {

struct ChildSpec {
  std::string executable;         // absolute
  std::vector<std::string> args;  // argv[1...]
  std::string log_path;           // stdout and stderr appended here
  long memory_limit_mb = 0;       // RLIMIT_AS of the child; 0: none
};

// Starts the child. Must be called from a thread that outlives it
// (PR_SET_PDEATHSIG follows the forking thread). Throws std::runtime_error
// when it cannot.
pid_t StartChild(const ChildSpec& spec);

struct ChildExit {
  int exit_code = -1;  // -1 when killed by a signal
  int signal = 0;
};
// The child's end when it has ended (reaped), nullopt while it runs.
std::optional<ChildExit> PollChild(pid_t pid);
// Sends `signal` to the child's process group.
void SignalChild(pid_t pid, int signal);

// The path of the running executable (/proc/self/exe resolved).
std::string SelfExecutable();

// True when `pid` is alive and its command line holds `needle` (a stale
// pid from the job store may have been reused by another process).
bool ProcessRunsWith(long pid, const std::string& needle);

}  // namespace zebrageo

#endif  // ZEBRAGEO_SERVER_CHILD_PROCESS_H_
