#include "feeddrive/service/loggers.hpp"

#include <dirent.h>
#include <sched.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "feeddrive/service/udpm_reader.hpp"

namespace feeddrive::service {
namespace {

// The inodes of the UDP sockets bound to `port` in this network namespace: /proc/net/udp and
// udp6, columns "sl local_address rem_address st ... inode", local_address "HEXIP:HEXPORT".
std::set<unsigned long> socket_inodes_on(int port) {
  std::set<unsigned long> out;
  for (const char* file : {"/proc/net/udp", "/proc/net/udp6"}) {
    std::ifstream in(file);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::istringstream f(line);
      std::string sl, local, remote, st, queues, tr, retr, uid, timeout;
      unsigned long inode = 0;
      if (!(f >> sl >> local >> remote >> st >> queues >> tr >> retr >> uid >> timeout >> inode)) continue;
      const std::size_t colon = local.rfind(':');
      if (colon == std::string::npos) continue;
      if (std::strtol(local.c_str() + colon + 1, nullptr, 16) == port && inode != 0) out.insert(inode);
    }
  }
  return out;
}

bool has_socket(const std::string& pid, const std::set<unsigned long>& inodes) {
  const std::string fd_dir = "/proc/" + pid + "/fd";
  DIR* d = ::opendir(fd_dir.c_str());
  if (d == nullptr) return false;
  bool found = false;
  char target[PATH_MAX];
  while (const dirent* e = ::readdir(d)) {
    if (e->d_name[0] == '.') continue;
    const std::string link = fd_dir + "/" + e->d_name;
    const ssize_t n = ::readlink(link.c_str(), target, sizeof target - 1);
    if (n <= 0) continue;
    target[n] = '\0';
    unsigned long inode = 0;
    if (std::sscanf(target, "socket:[%lu]", &inode) == 1 && inodes.count(inode)) {
      found = true;
      break;
    }
  }
  ::closedir(d);
  return found;
}

}  // namespace

std::vector<StockLogger> stock_loggers_on(const std::string& lcm_url) {
  std::vector<StockLogger> out;
  std::optional<UdpmAddress> a;
  try {
    a = parse_udpm_url(lcm_url);
  } catch (const std::exception&) {
    return out;
  }
  if (!a) return out;
  const std::set<unsigned long> inodes = socket_inodes_on(a->port);
  if (inodes.empty()) return out;
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return out;
  while (const dirent* e = ::readdir(proc)) {
    const std::string pid = e->d_name;
    if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream comm("/proc/" + pid + "/comm");
    std::string name;
    if (!std::getline(comm, name) || name != "lcm-logger") continue;
    if (!has_socket(pid, inodes)) continue;
    const int id = std::atoi(pid.c_str());
    const int policy = ::sched_getscheduler(id);
    out.push_back({id, name, policy == SCHED_FIFO || policy == SCHED_RR});
  }
  ::closedir(proc);
  return out;
}

std::string local_process_on_udp_port(int port) {
  const std::set<unsigned long> inodes = socket_inodes_on(port);
  if (inodes.empty()) return "";
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return "";
  std::string found;
  while (const dirent* e = ::readdir(proc)) {
    const std::string pid = e->d_name;
    if (pid.find_first_not_of("0123456789") != std::string::npos || !has_socket(pid, inodes)) continue;
    std::ifstream comm("/proc/" + pid + "/comm");
    std::string name;
    std::getline(comm, name);
    found = (name.empty() ? "a process" : name) + " (pid " + pid + ")";
    break;
  }
  ::closedir(proc);
  return found;
}

std::string describe(const std::vector<StockLogger>& loggers) {
  std::string s;
  for (const StockLogger& l : loggers)
    s += (s.empty() ? "" : ", ") + l.name + " (pid " + std::to_string(l.pid) +
         (l.realtime ? ", real-time priority)" : ", normal priority)");
  return s;
}

double stock_logger_pace(const std::vector<StockLogger>& loggers) {
  for (const StockLogger& l : loggers)
    if (!l.realtime) return kStockLoggerStepsNormal;
  return kStockLoggerSteps;
}

}  // namespace feeddrive::service
