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

namespace feeddrive::fit {

class DataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class InputKind {
  kCommand,  ///< u in the model's input unit: thrust = Ka*Kf*u
  kForce,    ///< force_N: the thrust [N]
};

struct MeasuredData {
  std::string source;               ///< file name, for messages
  std::vector<double> t;            ///< sample times [s], strictly increasing
  std::vector<double> x;            ///< measured position [m]
  std::vector<double> input;        ///< u [V] or thrust [N], held from t[k] to t[k+1]
  InputKind input_kind{InputKind::kCommand};
  std::vector<double> xd;           ///< reference [m], empty if absent
  std::vector<double> v;            ///< measured velocity [m/s], empty if absent
  double time_offset{0.0};          ///< subtracted from the file's time stamps (t[0] is 0) [s]
  std::vector<std::string> notes;   ///< what the loader did to the record (report.md, findings.json)
  std::size_t size() const { return t.size(); }
  /// Median sample period [s].
  double median_period() const;
};

/// Fewest samples accepted.
constexpr std::size_t kMinSamples = 50;

/// The CSV columns of each role (a drive's own export names them as it likes).
struct CsvOptions {
  std::string time_column{"t"};          ///< time [s]
  std::string position_column{"x"};      ///< the measured position [m]
  std::string command_column{"u"};       ///< the command in the model's unit (thrust = Ka*Kf*u)
  std::string force_column{"force_N"};   ///< or the thrust [N] (used when the command column is absent)
  std::string reference_column{"xd"};    ///< optional position reference [m]
};

/// Reads a CSV file (see above). Throws DataError.
MeasuredData load_csv(const std::string& path, const CsvOptions& opt = {});
/// Parses CSV text; `origin` names it in messages.
MeasuredData parse_csv(const std::string& text, const std::string& origin, const CsvOptions& opt = {});
/// Reads an LCM log written by lcm-logger (channels <prefix>_STATE/_REF/_CMD). Every step needs
/// its state and the next one (position, and the input applied during the step); a step whose
/// command was lost (the stock logger drops messages) uses the applied input the plant reports
/// in the next state, and one whose reference was lost costs only the optional xd column; both
/// are noted. A lost state is a gap the fit cannot bridge: DataError naming how many steps are
/// missing and where. Throws DataError.
MeasuredData load_lcm_log(const std::string& path, const std::string& prefix);
/// Loads by extension: .lcm / .lcmlog / .log -> LCM log, anything else -> CSV. Time stamps are
/// shifted to start at 0 (time_offset): epoch time stamps (t ~ 1e9 s) would leave the
/// integrator a step size below the resolution of t.
MeasuredData load_data(const std::string& path, const std::string& prefix, const CsvOptions& opt = {});

/// Subtracts t[0] from every time stamp (adds it to time_offset, with a note). Throws DataError
/// if two time stamps become equal.
void shift_time_origin(MeasuredData& d);

/// Checks sizes, finiteness and strictly increasing time (used by the loaders). Throws DataError.
void validate(const MeasuredData& d);

}  // namespace feeddrive::fit
