#include "feeddrive/monitor/log_reader.hpp"

#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/service/bus.hpp"

namespace feeddrive::monitor {
namespace {

template <typename Msg, typename F>
void decode_into(const lcm::LogEvent& ev, LogConversion& out, F&& f) {
  Msg m;
  if (m.decode(ev.data, 0, static_cast<int>(ev.datalen)) < 0) {
    ++out.undecodable;
    return;
  }
  f(m, ev.timestamp);
}

}  // namespace

LogConversion read_log(const std::string& path, const std::string& prefix) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::invalid_argument(path + ": cannot open the LCM log");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  const service::Channels ch(prefix);
  LogConversion out;
  for (;;) {
    const lcm::LogEvent* ev = log.readNextEvent();
    if (ev == nullptr) {
      // NULL at the end of the file is the normal end; NULL before it is a corrupt event.
      const long pos = std::ftell(log.getFilePtr());
      if (!ec && pos >= 0 && static_cast<std::uintmax_t>(pos) < size)
        throw std::invalid_argument(path + ": corrupt LCM log after event " + std::to_string(out.events) +
                                    " (byte " + std::to_string(pos) + " of " + std::to_string(size) + ")");
      break;
    }
    ++out.events;
    if (ev->channel == ch.state) {
      decode_into<drive_state_t>(*ev, out, [&](const drive_state_t& m, std::int64_t t) { out.recorder.on_state(m, t); });
    } else if (ev->channel == ch.reference) {
      decode_into<reference_block_t>(*ev, out, [&](const reference_block_t& b, std::int64_t t) {
        for (const reference_t& m : b.refs) out.recorder.on_reference(m, t);
      });
    } else if (ev->channel == ch.command) {
      decode_into<control_command_t>(*ev, out, [&](const control_command_t& m, std::int64_t t) { out.recorder.on_command(m, t); });
    } else {
      ++out.foreign_events;
    }
  }
  out.recorder.flush();
  return out;
}

}  // namespace feeddrive::monitor
