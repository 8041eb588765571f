#pragma once
// Sanity of a record against the scenario, before any fit (docs/fit.md, "Sanity before fitting").
// A record that cannot be what the scenario describes is refused with one line (DataError, exit 2)
// naming the column and the likely unit, or the row and the size of a jump:
//   * time: a step of more than kMaxGap median periods is a gap or a jump (two recordings joined);
//     a median period ~1000x or ~1e6x the scenario's control period is a time column in ms or us,
//     ~1/1000 of it one in ks (or s read as ms) when the speed confirms it; one above
//     kMaxSamplePeriodRatio control periods samples slower than the thrust changes;
//   * position: a travel above kMaxTravel or a speed above kMaxSpeed is beyond a feed drive (a
//     column in mm, um or nm); a step whose acceleration is beyond 4x what the peak thrust gives
//     the mass (and beyond 50x the sensor's own second difference and 5x the record's 99th
//     percentile of it) is a discontinuity, and so is a smaller step of a few um: a doublet in the
//     second difference (+J then -J, where a step of the thrust changes its level once) beyond 20
//     sensor steps (q + 3 noise sigma) and 8x the record's own scale of it. Either is named at its
//     row with its size: an isolated outlier (one sample off) as an outlier, a step as a step,
//     with the time's gap when the time jumps there too;
//   * force: the thrust must move the model's mass. The filtered thrust is regressed on
//     m * (filtered acceleration), a constant, sgn v and v (the modulating-function balance of
//     model.hpp with a generic friction); the ratio of thrust to m*a must lie within a factor
//     kMaxForceRatio of 1 (a 2x mass error passes; a force in kN read as N gives 0.001). The
//     position's smallest step against the scenario's encoder step tells which column is off: the
//     position when its steps are 1000x off, the force when they are the encoder's. A negative
//     ratio is a column whose sign is reversed; a constant input while the drive moves, a channel
//     switched off.

#include <string>

#include "feeddrive/fit/data.hpp"
#include "feeddrive/fit/model.hpp"
#include "feeddrive/plant/params.hpp"

namespace feeddrive::fit {

constexpr double kMaxGap = 10.0;         ///< a time step longer than this many median periods is a gap
constexpr double kMaxTravel = 10.0;      ///< [m] no feed drive travels further
constexpr double kMaxSpeed = 10.0;       ///< [m/s] nor faster (fast linear motors reach ~5 m/s)
constexpr double kMaxForceRatio = 30.0;  ///< thrust / (m a) outside [1/30, 30]: a unit off by 1000
/// thrust / (m a) at or below -1/this: a column's sign reversed (a mass error of 2x gives 0.5-2)
constexpr double kMaxSignRatio = 2.0;
/// a median sample period above this many control periods: the thrust is not held over a sample
constexpr double kMaxSamplePeriodRatio = 1.5;

/// The time and position checks on the raw record (before prepare()). control_period <= 0: no
/// time-scale check. Throws DataError. Returns what passed but the report should say (data
/// notes: time gaps shorter than kMaxGap periods, which the fit takes as they are).
std::vector<std::string> check_record(const MeasuredData& d, const plant::PlantParams& model, double control_period);

/// The force-scale check on a prepared record. Throws DataError.
void check_force_scale(const Record& rec, const plant::PlantParams& model);

/// The unit a factor to SI names for a role ("t", "x", "force", "u"), or "" if none does.
std::string unit_name(const std::string& role, double factor);

}  // namespace feeddrive::fit
