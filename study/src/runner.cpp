#include "feeddrive/study/runner.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "feeddrive/common/interrupt.hpp"
#include "feeddrive/sim/scenario.hpp"
#include "feeddrive/sim/simulation.hpp"
#include "feeddrive/sim/summary.hpp"

namespace feeddrive::study {

Outcome run_case(const sim::Scenario& s, const interrupt::StopToken& stop) {
  Outcome o;
  const auto start = std::chrono::steady_clock::now();
  try {
    // Streamed: the online summary keeps no records (memory independent of the run's length).
    sim::SummaryBuilder builder(s);
    const sim::RunStats st = sim::run(
        s, [&builder](const sim::Record& q) { builder.add(q); }, stop);
    const sim::Summary sum = builder.summary(st.wall_time_s, st.integrator);
    o.metrics = sim::summary_metrics(sum, s);
    o.warnings = s.warnings;
    o.move_finished = sim::move_finished(s);
    o.ok = true;
  } catch (const interrupt::Interrupted& e) {
    o.ok = false;
    o.interrupted = true;
    o.error = e.what();
  } catch (const std::exception& e) {
    o.ok = false;
    o.error = e.what();
    for (char& c : o.error)
      if (c == '\n' || c == '\r') c = ' ';
    o.metrics.clear();
    o.warnings.clear();
    o.move_finished.reset();
  }
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return o;
}

std::string outcome_json(const std::string& hash, const Outcome& o) {
  nlohmann::ordered_json j;
  j["format"] = kOutcomeFormat;
  j["hash"] = hash;
  j["ok"] = o.ok;
  j["error"] = o.error;
  nlohmann::ordered_json m = nlohmann::ordered_json::object();
  for (const auto& [k, v] : o.metrics) {
    // JSON has no NaN or infinity: those are written as strings and read back.
    if (std::isfinite(v)) {
      m[k] = v;
    } else {
      m[k] = std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    }
  }
  j["metrics"] = m;
  j["warnings"] = o.warnings;
  j["move_finished"] = o.move_finished ? nlohmann::ordered_json(*o.move_finished) : nlohmann::ordered_json();
  j["wall_s"] = o.wall_s;
  return j.dump(1) + "\n";
}

std::optional<Outcome> parse_outcome(const std::string& text, const std::string& hash) {
  try {
    const nlohmann::ordered_json j = nlohmann::ordered_json::parse(text);
    if (!j.is_object() || j.value("format", 0) != kOutcomeFormat || j.value("hash", std::string()) != hash)
      return std::nullopt;
    Outcome o;
    o.ok = j.at("ok").get<bool>();
    o.error = j.at("error").get<std::string>();
    for (auto it = j.at("metrics").begin(); it != j.at("metrics").end(); ++it) {
      double v = 0.0;
      if (it.value().is_number()) {
        v = it.value().get<double>();
      } else {
        const std::string s = it.value().get<std::string>();
        v = s == "nan" ? NAN : s == "inf" ? INFINITY : s == "-inf" ? -INFINITY : throw std::runtime_error("bad metric");
      }
      o.metrics.emplace_back(it.key(), v);
    }
    o.warnings = j.at("warnings").get<std::vector<std::string>>();
    if (!j.at("move_finished").is_null()) o.move_finished = j.at("move_finished").get<bool>();
    o.wall_s = j.at("wall_s").get<double>();
    if (o.ok == o.metrics.empty()) return std::nullopt;
    return o;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

Pool::Pool(int threads, std::function<Outcome(std::size_t)> work) : work_(std::move(work)) {
  for (int i = 0; i < std::max(1, threads); ++i) workers_.emplace_back([this] { loop(); });
}

Pool::~Pool() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
    tasks_.clear();
  }
  task_cv_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void Pool::push(std::size_t task) {
  {
    std::lock_guard<std::mutex> lock(mu_);
    tasks_.push_back(task);
    ++in_flight_;
  }
  task_cv_.notify_one();
}

std::size_t Pool::in_flight() const {
  std::lock_guard<std::mutex> lock(mu_);
  return in_flight_;
}

std::optional<std::pair<std::size_t, Outcome>> Pool::pop(std::chrono::milliseconds wait) {
  std::unique_lock<std::mutex> lock(mu_);
  if (!done_cv_.wait_for(lock, wait, [this] { return !done_.empty(); })) return std::nullopt;
  auto r = std::move(done_.front());
  done_.pop_front();
  --in_flight_;
  return r;
}

void Pool::loop() {
  for (;;) {
    std::size_t task = 0;
    {
      std::unique_lock<std::mutex> lock(mu_);
      task_cv_.wait(lock, [this] { return stop_ || !tasks_.empty(); });
      if (stop_) return;
      task = tasks_.front();
      tasks_.pop_front();
    }
    Outcome o = work_(task);
    {
      std::lock_guard<std::mutex> lock(mu_);
      done_.emplace_back(task, std::move(o));
    }
    done_cv_.notify_all();
  }
}

}  // namespace feeddrive::study
