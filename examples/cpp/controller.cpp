// An external controller in C++ built against the installed feeddrive SDK (find_package(feeddrive)):
// the project's sliding-mode law (feeddrive::controller::SlidingModeController, Xie & Liang eqs.
// 16-19) behind the LCM step protocol of docs/external-controllers.md, configured from the run's
// run_info_t. It uses only what a controller on hardware has: the measured position and
// velocity, and observers for the bristle and grinding states (no "truth").
//   sliding-mode-controller [LCM_URL [PREFIX]]     (after feeddrive-launch SCENARIO --out DIR --external controller)
// Protocol: answer state k once when reference k is known; repeat the same command for a
// repeated state or a resend request; ask for a missing reference; wait for run_info_t (every
// second) and stamp its run_id on everything published; heartbeat
// every 100 ms; stop at the end-of-run state, linger until the monitor is done; fail (exit 1,
// one line, status "failed") when another role fails or nothing comes for 5 s (30 s at the start).
#include <poll.h>
#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "feeddrive/common/fields.hpp"
#include "feeddrive/control_command_t.hpp"
#include "feeddrive/controller/sliding_mode.hpp"
#include "feeddrive/drive_state_t.hpp"
#include "feeddrive/process_status_t.hpp"
#include "feeddrive/reference_block_t.hpp"
#include "feeddrive/resend_request_t.hpp"
#include "feeddrive/run_info_t.hpp"

namespace fd = feeddrive;

namespace {

constexpr std::int32_t kContractVersion = 4;  // the contract of lcmtypes/ this example is built from

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
std::int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The drive's parameters of run_info_t.plant (every key of the plant's list, contract 4) set in
// the model through the model's own list (fields::unflatten): delta, the smoothed sign's shape and
// the ripple's harmonics included, and any key a later feeddrive adds to both. Throws on a
// parameter the model cannot take (an unknown friction law).
fd::plant::PlantParams model_from(const fd::run_info_t& info) {
  std::vector<fd::fields::FlatValue> table;
  for (const fd::parameter_t& p : info.plant) table.push_back({p.key, p.value, p.name, !p.name.empty()});
  fd::plant::PlantParams m;
  const std::size_t set = fd::fields::unflatten(m, [&](const std::string& key) -> const fd::fields::FlatValue* {
    for (const fd::fields::FlatValue& v : table)
      if (v.key == key) return &v;
    return nullptr;
  });
  if (set == 0) throw std::runtime_error("run_info_t.plant has no parameter of the model (contract 4?)");
  return m;
}

// The controller of the run, from its self-description: the drive's nominal model and limits,
// the paper's gains with a near-deadbeat boundary layer, observers instead of the true states.
fd::controller::SlidingModeParams params_from(const fd::run_info_t& info) {
  fd::controller::SlidingModeParams p;
  p.switching = fd::controller::Switching::kSaturation;
  p.boundary_layer = 5e-4;  // m/s: (lambda + eta/phi + k)*T = 1.006 at 10 kHz
  p.friction_state = fd::controller::StateSource::kObserver;
  p.grinding_state = fd::controller::StateSource::kObserver;
  p.u_min = info.u_min;
  p.u_max = info.u_max;
  p.period = info.control_period;
  p.model = model_from(info);
  return p;
}

class Node {
 public:
  Node(const std::string& url, const std::string& prefix) : lc_(url), p_(prefix) {
    if (!lc_.good()) throw std::runtime_error("cannot open LCM at " + url);
    raw(p_ + "_STATE", &Node::on_state);
    raw(p_ + "_REF", &Node::on_reference);
    raw(p_ + "_STATUS", &Node::on_status);
    raw(p_ + "_RESEND", &Node::on_resend);
    raw(p_ + "_INFO", &Node::on_info);
  }

  int run() {
    double last_beat = -1, last_request = -1;
    last_progress_ = now_s();
    while (!ended_) {
      handle(1);
      const double t = now_s();
      if (controller_ && pending_ && t - last_request > 0.002) request(p_ + "_REF", pending_->seq), last_request = t;
      if (!failure_.empty()) return fail(failure_);
      const double limit = next_seq_ == 0 ? 30.0 : 5.0;
      if (t - last_progress_ > limit)
        return fail("no state from the plant for step " + std::to_string(next_seq_) + " within " +
                    std::to_string(static_cast<int>(limit)) + " s");
      if (controller_ && t - last_beat >= 0.1) status("running"), last_beat = t;
    }
    status("done");
    for (const double end = now_s(); !monitor_done_ && now_s() - end < 10.0;) {
      handle(20);
      if (now_s() - last_beat >= 0.1) status("done"), last_beat = now_s();
    }
    std::fprintf(stderr, "sliding-mode-controller: %lld steps, %lld invalid messages\n",
                 static_cast<long long>(next_seq_), static_cast<long long>(invalid_));
    return 0;
  }

 private:
  using Handler = void (Node::*)(const lcm::ReceiveBuffer*);
  // Raw subscriptions: a message that does not decode is counted, not printed and dropped.
  void raw(const std::string& channel, Handler h) {
    struct Thunk {
      Node* n;
      Handler h;
      void handle(const lcm::ReceiveBuffer* rb, const std::string&) { (n->*h)(rb); }
    };
    thunks_.push_back(std::make_unique<Thunk>(Thunk{this, h}));
    lc_.subscribe(channel, &Thunk::handle, static_cast<Thunk*>(thunks_.back().get()));
  }
  template <typename Msg>
  bool decode(const lcm::ReceiveBuffer* rb, Msg& m) {
    if (m.decode(rb->data, 0, static_cast<int>(rb->data_size)) >= 0) return true;
    ++invalid_;
    return false;
  }
  void handle(int timeout_ms) {
    pollfd p{lc_.getFileno(), POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) > 0) lc_.handle();
  }

  void on_info(const lcm::ReceiveBuffer* rb) {
    fd::run_info_t info;
    if (controller_ || !decode(rb, info)) return;
    if (info.contract_version != kContractVersion) {
      failure_ = "run_info_t of contract version " + std::to_string(info.contract_version) +
                 ", this controller speaks " + std::to_string(kContractVersion) + " (docs/lcm-contract.md, Versions)";
      return;
    }
    fd::controller::SlidingModeParams p;
    try {
      p = params_from(info);
    } catch (const std::exception& e) {
      failure_ = std::string("run_info_t: ") + e.what();
      return;
    }
    controller_ = std::make_unique<fd::controller::SlidingModeController>(p);
    run_id_ = info.run_id;  // stamped on everything published: messages of another run are ignored
    const fd::plant::FrictionParams& f = p.model.friction;
    std::fprintf(stderr,
                 "sliding-mode-controller: run %s (%s): T = %g s, %lld steps, m = %g kg, Ka*Kf = %g N/V, friction %s "
                 "(Fs %g N, Fc %g N, vs %g m/s, delta %g)\n",
                 info.scenario.c_str(), info.mode.c_str(), info.control_period, static_cast<long long>(info.steps),
                 p.model.mass, p.model.thrust_gain(), fd::plant::to_string(f.model).c_str(), f.static_force,
                 f.coulomb_force, f.stribeck_velocity, f.stribeck_exponent);
    try_answer();
  }
  void on_state(const lcm::ReceiveBuffer* rb) {
    fd::drive_state_t m;
    if (!decode(rb, m)) return;
    if (m.end_of_run) {
      ended_ = true;
    } else if (m.seq < next_seq_) {  // answered already: the command got lost
      if (const auto c = sent_.find(m.seq); c != sent_.end()) lc_.publish(p_ + "_CMD", &c->second);
    } else if (!pending_ || pending_->seq != m.seq) {
      pending_ = m;
      try_answer();
    }
  }
  void on_reference(const lcm::ReceiveBuffer* rb) {
    fd::reference_block_t b;
    if (!decode(rb, b)) return;
    for (const fd::reference_t& r : b.refs)
      if (r.seq >= next_seq_) refs_[r.seq] = r;
    try_answer();
  }
  void on_status(const lcm::ReceiveBuffer* rb) {
    fd::process_status_t m;
    if (!decode(rb, m) || m.role == "controller") return;
    if (m.state == "failed" && failure_.empty())
      failure_ = m.role + " failed at step " + std::to_string(m.seq) + ": " + m.message;
    if (m.role == "monitor" && (m.state == "done" || m.state == "failed")) monitor_done_ = true;
  }
  void on_resend(const lcm::ReceiveBuffer* rb) {
    fd::resend_request_t r;
    if (!decode(rb, r) || r.channel != p_ + "_CMD") return;
    if (const auto c = sent_.find(r.seq); c != sent_.end()) lc_.publish(p_ + "_CMD", &c->second);
  }

  void try_answer() {
    if (!controller_ || !pending_) return;
    const auto r = refs_.find(pending_->seq);
    if (r == refs_.end()) return;
    const fd::drive_state_t st = *pending_;
    pending_.reset();
    fd::plant::Measurement meas;
    meas.t = st.t;
    meas.x = st.x_measured;
    meas.v = st.v_measured;
    const fd::trajectory::Sample ref{r->second.position, r->second.velocity, r->second.acceleration, r->second.jerk};
    const fd::controller::Command u = controller_->update(ref, meas, nullptr);  // once per step
    fd::control_command_t c{};
    c.run_id = run_id_;
    c.seq = st.seq;
    c.t = st.t;
    c.u = std::isfinite(u.u) ? u.u : 0.0;
    c.u_unsaturated = u.u_unsaturated;
    c.sliding = u.sliding;
    c.z_estimate = u.z_estimate;
    sent_[st.seq] = c;
    if (sent_.size() > 65536) sent_.erase(sent_.begin());
    lc_.publish(p_ + "_CMD", &c);
    next_seq_ = st.seq + 1;
    last_progress_ = now_s();
    refs_.erase(refs_.begin(), refs_.upper_bound(st.seq));
  }

  void status(const std::string& state, const std::string& message = "") {
    fd::process_status_t m{};
    m.run_id = run_id_;
    m.utime = wall_us();
    m.role = "controller";
    m.state = state;
    m.seq = next_seq_ - 1;
    m.acked_seq = -1;
    m.contract_version = kContractVersion;  // docs/lcm-contract.md, Versions
    m.message = message;
    m.invalid = invalid_;
    lc_.publish(p_ + "_STATUS", &m);
  }
  void request(const std::string& channel, std::int64_t seq) {
    fd::resend_request_t r{};
    r.run_id = run_id_;
    r.requester = "controller";
    r.channel = channel;
    r.seq = seq;
    lc_.publish(p_ + "_RESEND", &r);
  }
  int fail(const std::string& message) {
    for (int i = 0; i < 3; ++i) status("failed", message);
    std::fprintf(stderr, "sliding-mode-controller: error: %s\n", message.c_str());
    return 1;
  }

  lcm::LCM lc_;
  std::string p_;
  std::vector<std::shared_ptr<void>> thunks_;
  std::unique_ptr<fd::controller::SlidingModeController> controller_;
  std::optional<fd::drive_state_t> pending_;
  std::map<std::int64_t, fd::reference_t> refs_;
  std::map<std::int64_t, fd::control_command_t> sent_;
  std::int64_t next_seq_{0}, invalid_{0}, run_id_{0};
  double last_progress_{0};
  bool ended_{false}, monitor_done_{false};
  std::string failure_;
};

}  // namespace

int main(int argc, char** argv) {
  try {
    Node node(argc > 1 ? argv[1] : "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304", argc > 2 ? argv[2] : "FD");
    return node.run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sliding-mode-controller: error: %s\n", e.what());
    return 1;
  }
}
