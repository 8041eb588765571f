#pragma once
// Measured data of a drive, as feeddrive-fit reads it (docs/fit.md, "Data").
//
// CSV: a header line, then one row per sample. Required columns: `t` [s, strictly increasing],
// `x` [m, measured position] and one input column: `u` [the model's input unit; thrust =
// Ka*Kf*u] or `force_N` [N, the thrust itself]. Optional: `xd` [m], `v` [m/s]. Other columns are
// ignored. An LCM log (lcm-logger) of a run: the rows the monitor would record (measured x,
// applied u, xd) of the channels <prefix>_STATE/_REF/_CMD.
//
// Every problem is a DataError with one line naming the file, the line and the column.

#include <stdexcept>
#include <string>
#include <vector>

#include "feeddrive/common/errors.hpp"
#include "feeddrive/common/interrupt.hpp"

namespace feeddrive::fit {

class DataError : public BadInput {
 public:
  using BadInput::BadInput;
};

enum class InputKind {
  kCommand,  ///< u in the model's input unit: thrust = Ka*Kf*u
  kForce,    ///< force_N: the thrust [N]
};

struct MeasuredData {
  std::string source;         ///< file name, for messages
  std::vector<double> t;      ///< sample times [s], strictly increasing
  std::vector<double> x;      ///< measured position [m]
  std::vector<double> input;  ///< u [V] or thrust [N], held from t[k] to t[k+1]
  InputKind input_kind{InputKind::kCommand};
  std::vector<double> xd;          ///< reference [m], empty if absent
  std::vector<double> v;           ///< measured velocity [m/s], empty if absent
  double time_offset{0.0};         ///< subtracted from the file's time stamps (t[0] is 0) [s]
  std::vector<std::string> notes;  ///< what the loader did to the record (report.md, findings.json)
  /// The file line of each sample (CSV; empty for an LCM log), for messages naming a row.
  std::vector<long> lines;
  /// The file's names of the time, position and input columns (for messages).
  std::string time_name{"t"}, position_name{"x"}, input_name{"u"};
  /// The unit factors applied to them on loading (SI = factor * file value; CsvOptions::units).
  double time_factor{1.0}, position_factor{1.0}, input_factor{1.0};
  /// "where sample k is": "FILE:LINE" of a CSV, "FILE, step k" of a log.
  std::string where(std::size_t k) const;
  std::size_t size() const { return t.size(); }
  /// Median sample period [s].
  double median_period() const;
};

/// The record's own position resolution: its smallest nonzero step between consecutive samples [m]
/// (0 if the position never changes).
double smallest_position_step(const MeasuredData& d);

/// Fewest samples accepted.
constexpr std::size_t kMinSamples = 50;

/// The unit of each column role, as a factor to SI (docs/fit.md, "Data"): parsed from
/// "ROLE=UNIT[,ROLE=UNIT...]" with ROLE one of t, x, u, force, xd and UNIT
///   t: s, ms, us;   x, xd: m, mm, um, nm;   force: N, kN, mN;   u: V, mV;
///   any role: counts:S (S of the SI unit per count, e.g. x=counts:5e-8 for a 50 nm encoder).
/// Throws DataError naming the bad entry.
struct Units {
  double t{1.0}, x{1.0}, u{1.0}, force{1.0}, xd{1.0};
  std::string text;  ///< as given, for messages
};
Units parse_units(const std::string& spec);

/// The CSV columns of each role (a drive's own export names them as it likes). A column is named
/// by its header name or, if the header has no such name, by its 1-based index ("2").
struct CsvOptions {
  char separator{','};                  ///< column separator (',', ';', '\t')
  bool decimal_comma{false};            ///< "0,25" means 0.25
  Units units;                          ///< unit of each role (SI by default)
  std::string time_column{"t"};         ///< time [s]
  std::string position_column{"x"};     ///< the measured position [m]
  std::string command_column{"u"};      ///< the command in the model's unit (thrust = Ka*Kf*u)
  std::string force_column{"force_N"};  ///< or the thrust [N] (used when the command column is absent)
  std::string reference_column{"xd"};   ///< optional position reference [m]
};

/// Reads a CSV file (see above). Throws DataError.
MeasuredData load_csv(const std::string& path, const CsvOptions& opt = {});
/// Reads an LCM log written by lcm-logger (channels <prefix>_STATE/_REF/_CMD). Every step needs
/// its state and the next one (position, and the input applied during the step); a step whose
/// command was lost (the stock logger drops messages) uses the applied input the plant reports
/// in the next state, and one whose reference was lost costs only the optional xd column; both
/// are noted. A lost state is a gap the fit cannot bridge: DataError naming how many steps are
/// missing and where. Throws DataError.
MeasuredData load_lcm_log(const std::string& path, const std::string& prefix, const interrupt::StopToken& stop = {});
/// Loads by extension: .lcm / .lcmlog / .log -> LCM log, anything else -> CSV. Time stamps are
/// shifted to start at 0 (time_offset): epoch time stamps (t ~ 1e9 s) would leave the
/// integrator a step size below the resolution of t.
MeasuredData load_data(const std::string& path, const std::string& prefix, const CsvOptions& opt = {},
                       const interrupt::StopToken& stop = {});

/// Subtracts t[0] from every time stamp (adds it to time_offset, with a note). Throws DataError
/// if two time stamps become equal.
void shift_time_origin(MeasuredData& d);

/// Checks sizes, finiteness and strictly increasing time (used by the loaders). Throws DataError.
void validate(const MeasuredData& d);

}  // namespace feeddrive::fit
