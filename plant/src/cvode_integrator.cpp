#include "feeddrive/plant/cvode_integrator.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "feeddrive/common/validate.hpp"

namespace feeddrive::plant {
namespace {

void check_flag(int flag, const char* call) {
  if (flag < 0) throw std::runtime_error(std::string("CVODE: ") + call + " failed with flag " + std::to_string(flag));
}
template <typename T>
T* check_ptr(T* p, const char* call) {
  if (p == nullptr) throw std::runtime_error(std::string("CVODE: ") + call + " returned NULL");
  return p;
}

struct UserData {
  const EffectiveParams* params{nullptr};  ///< the effects folded in once, at construction
  /// CVODE holds only the active states (dynamics.hpp active_states): full index of each.
  std::array<int, kStateSize> index{};
  int n{0};
  StateVector held{};  ///< values of the inactive states (constant)
  double u{0.0};
  // The period's start: CVODE integrates the deviations from the constant-acceleration
  // Taylor prediction of the period  x = x0 + v0*tau + a0*tau^2/2 + j0*tau^3/6 + y_x,
  // v = v0 + a0*tau + j0*tau^2/2 + y_v,  tau = t - t0.
  double t0{0.0};
  double x0{0.0};
  double v0{0.0};
  double a0{0.0};
  double j0{0.0};
};

// Full physical state from CVODE's compact vector y at time t. x and v are always active and
// come first (index 0 and 1).
State state_of(sunrealtype t, N_Vector y, const UserData& ud) {
  const sunrealtype* d = N_VGetArrayPointer(y);
  StateVector full = ud.held;
  for (int j = 0; j < ud.n; ++j) full[ud.index[j]] = d[j];
  const double tau = t - ud.t0;
  full[kX] += ud.x0 + tau * (ud.v0 + tau * (0.5 * ud.a0 + tau * ud.j0 / 6.0));
  full[kV] += ud.v0 + tau * (ud.a0 + 0.5 * ud.j0 * tau);
  return State::from_vector(full);
}

// CVRhsFn: ydot = f(t, y) with the input held. Returns 1 (recoverable) on a non-finite value,
// so CVODE retries with a smaller step; never throws into C.
int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* user_data) {
  const auto* ud = static_cast<const UserData*>(user_data);
  StateVector d = derivative(*ud->params, state_of(t, y, *ud), ud->u);
  // d/dt y_x = v - (v0 + a0*tau + j0*tau^2/2) = y_v;  d/dt y_v = a - a0 - j0*tau.
  d[kX] = N_VGetArrayPointer(y)[kV];
  d[kV] -= ud->a0 + ud->j0 * (t - ud->t0);
  sunrealtype* out = N_VGetArrayPointer(ydot);
  for (int j = 0; j < ud->n; ++j) {
    const double value = d[ud->index[j]];
    if (!std::isfinite(value)) return 1;
    out[j] = value;
  }
  return 0;
}

// CVLsJacFn: dense analytic Jacobian df/dy (dynamics.hpp).
int jac(sunrealtype t, N_Vector y, N_Vector /*fy*/, SUNMatrix J, void* user_data, N_Vector, N_Vector, N_Vector) {
  const auto* ud = static_cast<const UserData*>(user_data);
  const Jacobian a = jacobian(*ud->params, state_of(t, y, *ud), ud->u);
  for (int r = 0; r < ud->n; ++r)
    for (int c = 0; c < ud->n; ++c) SM_ELEMENT_D(J, r, c) = a[ud->index[r]][ud->index[c]];
  return 0;
}

}  // namespace

struct CvodeIntegrator::Impl {
  explicit Impl(const PlantParams& p) : params(p), given(p) {}
  EffectiveParams params;
  PlantParams given;  ///< as the scenario states them: failure messages name these keys
  UserData user;
  SUNContext ctx{nullptr};
  N_Vector y{nullptr};
  N_Vector atol{nullptr};
  SUNMatrix A{nullptr};
  SUNLinearSolver LS{nullptr};
  void* mem{nullptr};
  CvodeIntegrator::Stats total;  ///< summed over the periods (CVodeReInit zeroes CVODE's own)

  void accumulate() {
    long n = 0;
    CVodeGetNumSteps(mem, &n);
    total.steps += n;
    CVodeGetNumRhsEvals(mem, &n);
    total.rhs_evals += n;
    CVodeGetNumJacEvals(mem, &n);
    total.jac_evals += n;
    CVodeGetNumErrTestFails(mem, &n);
    total.error_test_fails += n;
    CVodeGetNumNonlinSolvConvFails(mem, &n);
    total.nonlinear_fails += n;
  }

  ~Impl() {
    if (mem) CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (atol) N_VDestroy(atol);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

CvodeIntegrator::CvodeIntegrator(const PlantParams& params, double t0, const StateVector& y0)
    : impl_(std::make_unique<Impl>(params)), t_(t0), y_(y0) {
  Impl& m = *impl_;
  m.user.params = &m.params;
  const auto active = active_states(m.params);
  for (int i = 0; i < kStateSize; ++i)
    if (active[i]) m.user.index[m.user.n++] = i;
  const int n = m.user.n;
  const IntegratorParams& ip = params.integrator;
  const StateVector atol_full{ip.atol_position, ip.atol_velocity, ip.atol_bristle, ip.atol_grinding, ip.atol_current};

  check_flag(SUNContext_Create(nullptr, &m.ctx), "SUNContext_Create");
  m.y = check_ptr(N_VNew_Serial(n, m.ctx), "N_VNew_Serial");
  m.atol = check_ptr(N_VNew_Serial(n, m.ctx), "N_VNew_Serial");
  for (int j = 0; j < n; ++j) {
    N_VGetArrayPointer(m.y)[j] = 0.0;
    N_VGetArrayPointer(m.atol)[j] = atol_full[m.user.index[j]];
  }
  m.mem = check_ptr(CVodeCreate(CV_BDF, m.ctx), "CVodeCreate");
  check_flag(CVodeInit(m.mem, rhs, t0, m.y), "CVodeInit");
  check_flag(CVodeSetUserData(m.mem, &m.user), "CVodeSetUserData");
  check_flag(CVodeSVtolerances(m.mem, ip.rtol, m.atol), "CVodeSVtolerances");
  m.A = check_ptr(SUNDenseMatrix(n, n, m.ctx), "SUNDenseMatrix");
  m.LS = check_ptr(SUNLinSol_Dense(m.y, m.A, m.ctx), "SUNLinSol_Dense");
  check_flag(CVodeSetLinearSolver(m.mem, m.LS, m.A), "CVodeSetLinearSolver");
  check_flag(CVodeSetJacFn(m.mem, jac), "CVodeSetJacFn");
  check_flag(CVodeSetMaxNumSteps(m.mem, ip.max_steps), "CVodeSetMaxNumSteps");
  CVodeSetErrHandlerFn(
      m.mem, [](int, const char*, const char*, char*, void*) {}, nullptr);
}

CvodeIntegrator::~CvodeIntegrator() = default;

void CvodeIntegrator::reset(double t, const StateVector& y) {
  t_ = t;
  y_ = y;
}

void CvodeIntegrator::advance(double u, double t_next) {
  if (!(t_next > t_)) {
    if (t_next == t_) return;
    throw std::invalid_argument("CvodeIntegrator::advance: t_next " + std::to_string(t_next) +
                                " is before the current time " + std::to_string(t_));
  }
  Impl& m = *impl_;
  UserData& ud = m.user;
  ud.u = u;
  // Integrate the deviations of x and v from the constant-acceleration prediction of the period
  // (a change of variables; the Jacobian is unchanged). CVODE's error weight is
  // rtol*|y_i| + atol_i: on the absolute position (0.1 m) rtol = 1e-8 would allow 1 nm of error
  // per period, which the controller sees as a velocity disturbance of 1 nm / T (10 um/s at
  // T = 1e-4 s) and which would dominate every sub-um figure. The deviations keep the position
  // and velocity errors absolute and independent of where on the axis the move happens.
  ud.held = y_;
  ud.held[kX] = 0.0;
  ud.held[kV] = 0.0;
  ud.t0 = t_;
  ud.x0 = y_[kX];
  ud.v0 = y_[kV];
  {
    // a0 = dv/dt and j0 = d2v/dt2 = sum_j (df_v/dy_j) f_j at the period's start (u held).
    const State s0 = State::from_vector(y_);
    const StateVector f0 = derivative(m.params, s0, u);
    const Jacobian J0 = jacobian(m.params, s0, u);
    ud.a0 = f0[kV];
    ud.j0 = 0.0;
    for (int i = 0; i < kStateSize; ++i) ud.j0 += J0[kV][i] * f0[i];
    if (!std::isfinite(ud.j0)) ud.j0 = 0.0;
  }
  sunrealtype* yd = N_VGetArrayPointer(m.y);
  for (int j = 0; j < ud.n; ++j) yd[j] = ud.held[ud.index[j]];
  // Restart at the input discontinuity (CVODE guide, "jump discontinuities in the RHS"); CVODE
  // estimates the first step itself (fewer error-test failures than reusing the last step).
  check_flag(CVodeReInit(m.mem, t_, m.y), "CVodeReInit");
  check_flag(CVodeSetStopTime(m.mem, t_next), "CVodeSetStopTime");
  sunrealtype t_reached = t_;
  const int flag = CVode(m.mem, t_next, m.y, &t_reached, CV_NORMAL);
  m.accumulate();
  if (flag < 0)
    throw IntegrationError("CVODE: CVode failed with flag " + std::to_string(flag) + " (" +
                           CVodeGetReturnFlagName(flag) + ") at t = " + validate::format_number(t_reached) +
                           " with u = " + validate::format_number(u) + "; " + m.given.fastest_time_scales());
  y_ = state_of(t_next, m.y, ud).to_vector();
  t_ = t_next;  // exactly the boundary (CV_TSTOP_RETURN stops there)
}

CvodeIntegrator::Stats CvodeIntegrator::stats() const { return impl_->total; }

}  // namespace feeddrive::plant
