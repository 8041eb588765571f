#include "feeddrive/plant/cvode_integrator.hpp"

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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
  const PlantParams* params{nullptr};
  double u{0.0};
};

State state_of(N_Vector y) {
  const sunrealtype* d = N_VGetArrayPointer(y);
  return {d[kX], d[kV], d[kZ], d[kFg], d[kI]};
}

// CVRhsFn: ydot = f(t, y) with the input held. Returns 1 (recoverable) on a non-finite value,
// so CVODE retries with a smaller step; never throws into C.
int rhs(sunrealtype /*t*/, N_Vector y, N_Vector ydot, void* user_data) {
  const auto* ud = static_cast<const UserData*>(user_data);
  const StateVector d = derivative(*ud->params, state_of(y), ud->u);
  sunrealtype* out = N_VGetArrayPointer(ydot);
  for (int i = 0; i < kStateSize; ++i) {
    if (!std::isfinite(d[i])) return 1;
    out[i] = d[i];
  }
  return 0;
}

// CVLsJacFn: dense analytic Jacobian df/dy (dynamics.hpp).
int jac(sunrealtype /*t*/, N_Vector y, N_Vector /*fy*/, SUNMatrix J, void* user_data, N_Vector,
        N_Vector, N_Vector) {
  const auto* ud = static_cast<const UserData*>(user_data);
  const Jacobian a = jacobian(*ud->params, state_of(y), ud->u);
  for (int r = 0; r < kStateSize; ++r)
    for (int c = 0; c < kStateSize; ++c) SM_ELEMENT_D(J, r, c) = a[r][c];
  return 0;
}

}  // namespace

struct CvodeIntegrator::Impl {
  PlantParams params;
  UserData user;
  SUNContext ctx{nullptr};
  N_Vector y{nullptr};
  N_Vector atol{nullptr};
  SUNMatrix A{nullptr};
  SUNLinearSolver LS{nullptr};
  void* mem{nullptr};
  double last_step{0.0};

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
    : impl_(std::make_unique<Impl>()), t_(t0), y_(y0) {
  Impl& m = *impl_;
  m.params = params;
  m.user.params = &m.params;
  check_flag(SUNContext_Create(nullptr, &m.ctx), "SUNContext_Create");
  m.y = check_ptr(N_VNew_Serial(kStateSize, m.ctx), "N_VNew_Serial");
  m.atol = check_ptr(N_VNew_Serial(kStateSize, m.ctx), "N_VNew_Serial");
  std::copy(y0.begin(), y0.end(), N_VGetArrayPointer(m.y));
  const IntegratorParams& ip = params.integrator;
  sunrealtype* at = N_VGetArrayPointer(m.atol);
  at[kX] = ip.atol_position;
  at[kV] = ip.atol_velocity;
  at[kZ] = ip.atol_bristle;
  at[kFg] = ip.atol_grinding;
  at[kI] = ip.atol_current;

  m.mem = check_ptr(CVodeCreate(CV_BDF, m.ctx), "CVodeCreate");
  check_flag(CVodeInit(m.mem, rhs, t0, m.y), "CVodeInit");
  check_flag(CVodeSetUserData(m.mem, &m.user), "CVodeSetUserData");
  check_flag(CVodeSVtolerances(m.mem, ip.rtol, m.atol), "CVodeSVtolerances");
  m.A = check_ptr(SUNDenseMatrix(kStateSize, kStateSize, m.ctx), "SUNDenseMatrix");
  m.LS = check_ptr(SUNLinSol_Dense(m.y, m.A, m.ctx), "SUNLinSol_Dense");
  check_flag(CVodeSetLinearSolver(m.mem, m.LS, m.A), "CVodeSetLinearSolver");
  check_flag(CVodeSetJacFn(m.mem, jac), "CVodeSetJacFn");
  check_flag(CVodeSetMaxNumSteps(m.mem, ip.max_steps), "CVodeSetMaxNumSteps");
  CVodeSetErrHandlerFn(m.mem, [](int, const char*, const char*, char*, void*) {}, nullptr);
}

CvodeIntegrator::~CvodeIntegrator() = default;

void CvodeIntegrator::reset(double t, const StateVector& y) {
  t_ = t;
  y_ = y;
  impl_->last_step = 0.0;
}

void CvodeIntegrator::advance(double u, double t_next) {
  if (!(t_next > t_)) {
    if (t_next == t_) return;
    throw std::invalid_argument("CvodeIntegrator::advance: t_next " + std::to_string(t_next) +
                                " is before the current time " + std::to_string(t_));
  }
  Impl& m = *impl_;
  m.user.u = u;
  std::copy(y_.begin(), y_.end(), N_VGetArrayPointer(m.y));
  // Restart at the input discontinuity (CVODE guide, "jump discontinuities in the RHS").
  check_flag(CVodeReInit(m.mem, t_, m.y), "CVodeReInit");
  check_flag(CVodeSetStopTime(m.mem, t_next), "CVodeSetStopTime");
  // Start from the last accepted step size: skips CVODE's h0 estimate. Deterministic.
  if (m.last_step > 0.0) check_flag(CVodeSetInitStep(m.mem, std::min(m.last_step, t_next - t_)), "CVodeSetInitStep");
  sunrealtype t_reached = t_;
  const int flag = CVode(m.mem, t_next, m.y, &t_reached, CV_NORMAL);
  if (flag < 0)
    throw std::runtime_error("CVODE: CVode failed with flag " + std::to_string(flag) + " (" +
                             CVodeGetReturnFlagName(flag) + ") at t = " + std::to_string(t_reached));
  sunrealtype h = 0.0;
  CVodeGetLastStep(m.mem, &h);
  if (h > 0.0) m.last_step = h;
  const sunrealtype* d = N_VGetArrayPointer(m.y);
  std::copy(d, d + kStateSize, y_.begin());
  t_ = t_next;  // exactly the boundary (CV_TSTOP_RETURN stops there)
}

CvodeIntegrator::Stats CvodeIntegrator::stats() const {
  Stats s;
  CVodeGetNumSteps(impl_->mem, &s.steps);
  CVodeGetNumRhsEvals(impl_->mem, &s.rhs_evals);
  CVodeGetNumJacEvals(impl_->mem, &s.jac_evals);
  CVodeGetNumErrTestFails(impl_->mem, &s.error_test_fails);
  CVodeGetNumNonlinSolvConvFails(impl_->mem, &s.nonlinear_fails);
  return s;
}

}  // namespace feeddrive::plant
