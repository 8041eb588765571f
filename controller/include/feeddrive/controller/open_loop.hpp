#pragma once
// Open-loop force sources for the paper's open-loop studies (Xie & Liang Sec. 4). The source
// defines a force F(t) [N]; the command is u = F/(Ka*Kf) so that the thrust equals F.
//   step:  F = offset + amplitude           for t >= start_time, else offset
//   sine:  F = offset + amplitude*sin(2*pi*f*(t - start_time) + phase)   for t >= start_time
//   ramp:  F = offset + rate*(t - start_time)  for t >= start_time (capped at |amplitude| if > 0)
//   csv:   F from a table of rows (t_i, F_i) (or (t_i, u_i)), zero-order hold between rows, 0
//          before the first. The table is data: the scenario layer reads it from the CSV file
//          (feeddrive::csv, columns t and force_N or u); this library reads no files.

#include <string>
#include <utility>
#include <vector>

#include "feeddrive/controller/controller.hpp"
#include "feeddrive/controller/quantity.hpp"

namespace feeddrive::controller {

enum class OpenLoopKind { kStep, kSine, kRamp, kCsv };
inline const std::vector<std::pair<OpenLoopKind, const char*>>& enum_names(OpenLoopKind) {
  static const std::vector<std::pair<OpenLoopKind, const char*>> n = {{OpenLoopKind::kStep, "step"},
                                                                      {OpenLoopKind::kSine, "sine"},
                                                                      {OpenLoopKind::kRamp, "ramp"},
                                                                      {OpenLoopKind::kCsv, "csv"}};
  return n;
}
std::string to_string(OpenLoopKind k);

struct OpenLoopParams {
  OpenLoopKind kind{OpenLoopKind::kStep};
  double amplitude{12.0};           ///< [N] (step height, sine amplitude, ramp cap; 0 = no cap)
  double frequency{1.0};            ///< [Hz] (sine)
  double phase{0.0};                ///< [rad] (sine)
  double offset{0.0};               ///< [N]
  double rate{100.0};               ///< [N/s] (ramp)
  double start_time{0.0};           ///< [s]
  std::vector<double> table_t;      ///< csv: row times [s], strictly increasing
  std::vector<double> table_value;  ///< csv: force [N] (table_is_force) or u [V] of each row
  bool table_is_force{true};
  double thrust_gain{260.0};  ///< Ka*Kf [N/V] used to turn force into u
  double u_min{-1e9};         ///< [V]
  double u_max{1e9};          ///< [V]

  /// The scenario keys (controller.*); the table and thrust_gain come from the scenario
  /// (controller.file, the plant's Ka*Kf).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(FD_FIELD(kind).doc("step, sine, ramp or csv"));
    a->Visit(
        FD_FIELD(amplitude).unit("N").plausible(-1e5, 1e5).doc("step height, sine amplitude, ramp cap (0 = none)"));
    a->Visit(FD_FIELD(frequency).unit("Hz").non_negative().plausible(0, 1e4).doc("sine"));
    a->Visit(FD_FIELD(phase).unit("rad").plausible(-7, 7, "deg").doc("sine"));
    a->Visit(FD_FIELD(offset).unit("N").plausible(-1e5, 1e5).doc("added to every kind"));
    a->Visit(FD_FIELD(rate).unit("N/s").plausible(-1e7, 1e7).doc("ramp slope"));
    a->Visit(FD_FIELD(start_time).unit("s").non_negative().doc("before it only the offset acts"));
    a->Visit(quantity::u_min(u_min));
    a->Visit(quantity::u_max(u_max));
  }
  void validate(const std::string& prefix = "controller") const;
};

class OpenLoopSource final : public Controller {
 public:
  explicit OpenLoopSource(const OpenLoopParams& p);
  Command update(const trajectory::Sample& ref, const plant::Measurement& meas, const Truth* truth) override;
  std::string name() const override { return "open_loop"; }
  /// The force F(t) [N] of the source.
  double force(double t) const;

 private:
  OpenLoopParams p_;
  std::vector<double> csv_u_;  // csv rows: u [V]
};

}  // namespace feeddrive::controller
