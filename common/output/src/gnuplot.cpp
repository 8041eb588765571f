#include "feeddrive/output/gnuplot.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/common/text.hpp"

namespace feeddrive::output {
namespace fs = std::filesystem;

namespace {

bool safe_ascii(unsigned char c) {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return true;
  static constexpr std::string_view kPunctuation = " _-.,:;+/()[]=#%*!?<>|~^&";
  return kPunctuation.find(static_cast<char>(c)) != std::string_view::npos;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The last non-empty line of gnuplot's output, printable, for a one-line message.
std::string last_message(const std::string& log) {
  std::string last, line;
  std::istringstream in(log);
  while (std::getline(in, line)) {
    bool blank = true;
    for (char c : line) blank = blank && (c == ' ' || c == '\t' || c == '^' || c == '\r');
    if (!blank) last = line;
  }
  for (char& c : last)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

}  // namespace

std::string gnuplot_string(std::string_view text, std::size_t max_bytes) {
  std::string out = "\"";
  std::size_t kept = 0;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    std::size_t n = 1;
    std::string_view piece = "?";
    if (safe_ascii(c)) {
      piece = text.substr(i, 1);
    } else if (const std::size_t u = text::utf8_char(text, i); u > 0) {
      n = u;
      piece = text.substr(i, u);
    }
    if (kept + piece.size() > max_bytes) {
      out += "...";
      break;
    }
    out += piece;
    kept += piece.size();
    i += n;
  }
  return out + "\"";
}

void run_gnuplot(const fs::path& dir, const std::string& script, const interrupt::StopToken& stop,
                 const std::string& script_name) {
  const fs::path script_path = dir / script_name, log_path = dir / "gnuplot.log";
  {
    std::ofstream gp(script_path, std::ios::binary);
    gp << script;
    if (!gp) throw std::runtime_error(script_path.string() + ": write failed");
  }
  // Everything the child needs, prepared before fork: it only makes system calls.
  const std::string cwd = dir.string();
  char arg0[] = "gnuplot";
  std::string arg1 = script_name;
  char* const argv[] = {arg0, arg1.data(), nullptr};
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("gnuplot: fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    if (::chdir(cwd.c_str()) != 0) ::_exit(126);
    const int log = ::open("gnuplot.log", O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int null = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (log < 0 || null < 0 || ::dup2(null, 0) < 0 || ::dup2(log, 1) < 0 || ::dup2(log, 2) < 0) ::_exit(126);
    ::execvp(arg0, argv);
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error(std::string("gnuplot: waitpid failed: ") + std::strerror(errno));
    if (stop.stop_requested()) {  // Ctrl-C or SIGTERM: stop gnuplot at once, then unwind
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
      stop.check();
    }
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (code == 127) throw std::runtime_error("cannot run gnuplot (not installed? use --no-plots to skip the plots)");
  if (code != 0) {
    const std::string why = last_message(slurp(log_path));
    throw std::runtime_error("gnuplot failed (exit " + std::to_string(code) + ")" + (why.empty() ? "" : ": " + why));
  }
  std::error_code ec;
  fs::remove(log_path, ec);
}

}  // namespace feeddrive::output
