#include "feeddrive/fit/workflow.hpp"

#include <cstdio>

namespace feeddrive::fit {

namespace {
std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}
}  // namespace

FitResult run_fit(const Record& rec_in, const plant::PlantParams& model, const FitOptions& opt, const Log& log) {
  Record rec = rec_in;
  mask_stiction(rec, model);
  const auto say = [&](const std::string& s) {
    if (log) log(s);
  };
  FitResult out;
  out.initial = model;
  plant::PlantParams current = model;
  Eigen::VectorXd r = force_residual(rec, current);
  Replay rp = replay(rec, current, opt.replay_window);
  out.replay_initial = rp;
  out.force_rms_initial = rms(r, rec.active_points());
  say("initial model: gap " + fmt("%.4g um, force residual RMS %.4g N", rp.gap * 1e6, rms(r, rec.active_points())));
  std::vector<std::string> added;
  for (int it = 0; it < opt.max_effects; ++it) {
    StepResult st;
    st.localisation = localise(rec, r, rp);
    st.gap_before = rp.gap;
    st.force_rms_before = rms(r, rec.active_points());
    st.residual_before = r;
    st.ranking = rank_candidates(rec, current);
    if (st.ranking.empty()) break;
    // The best candidate that is significant, valid (its parameters pass the plant's
    // validate()) and confirmed by the replay; stop at the first significant one that is not
    // confirmed.
    const CandidateFit* best = &st.ranking.front();
    st.effect = best->effect;
    st.score = best->score;
    say("step " + std::to_string(it + 1) + ": best candidate " + best->effect.name + fmt(" (score %.4g)", best->score));
    plant::PlantParams trial;
    Eigen::VectorXd r2;
    Replay rp2;
    bool found = false;
    std::string why;
    for (const CandidateFit& c : st.ranking) {
      if (!(c.score >= opt.score_threshold)) break;
      trial = current;
      plant::set_effect(trial.effects, c.effect);
      trial = refine_jointly(rec, trial);
      try {
        trial.validate();
      } catch (const std::invalid_argument& e) {
        why += (why.empty() ? "" : "; ") + c.effect.name + " fitted to invalid values (" + e.what() + ")";
        continue;
      }
      try {
        r2 = force_residual(rec, trial);
        rp2 = replay(rec, trial, opt.replay_window);
      } catch (const std::runtime_error& e) {  // e.g. CVODE cannot integrate the fitted model
        why += (why.empty() ? "" : "; ") + c.effect.name + " cannot be replayed (" + e.what() + ")";
        continue;
      }
      best = &c;
      st.effect = c.effect;
      st.score = c.score;
      st.gap_after = rp2.gap;
      st.force_rms_after = rms(r2, rec.active_points());
      st.residual_after = r2;
      found = true;
      break;
    }
    if (!found) {
      st.verdict = "no significant effect: the best candidate, " + st.ranking.front().effect.name +
                   fmt(", scores %.3g (threshold %.3g)", st.ranking.front().score, opt.score_threshold) +
                   (why.empty() ? "" : "; " + why);
      st.gap_after = st.gap_before;
      st.force_rms_after = st.force_rms_before;
      st.residual_after = r;
      out.steps.push_back(st);
      break;
    }
    if (!(rp2.gap <= (1.0 - opt.min_gap_reduction) * rp.gap)) {
      st.verdict = "no significant effect: " + best->effect.name +
                   fmt(" scores %.3g but does not shrink the replay gap (%.4g -> %.4g um)", best->score,
                       rp.gap * 1e6, rp2.gap * 1e6);
      out.steps.push_back(st);
      break;
    }
    st.accepted = true;
    st.verdict = "added " + best->effect.name + fmt(": gap %.4g -> %.4g um", rp.gap * 1e6, rp2.gap * 1e6) +
                 (why.empty() ? "" : " (passed over: " + why + ")");
    say(st.verdict);
    out.steps.push_back(st);
    current = trial;
    r = r2;
    rp = rp2;
    added.push_back(best->effect.name);
  }
  out.fitted = current;
  out.replay_final = rp;
  out.force_rms_final = rms(r, rec.active_points());
  out.final_localisation = localise(rec, r, rp);
  // the added effects, in the order found, with their final parameters
  for (const std::string& name : added)
    for (const Effect& e : plant::enabled_effects(current.effects))
      if (e.name == name) out.effects.push_back(e);
  if (added.empty()) {
    out.conclusion = "no significant effect: the model explains the data to within its noise";
  } else {
    out.conclusion = "found " + std::to_string(added.size()) + " effect(s):";
    for (const auto& n : added) out.conclusion += " " + n;
    out.conclusion += fmt("; gap %.4g -> %.4g um", out.replay_initial.gap * 1e6, rp.gap * 1e6);
  }
  say(out.conclusion);
  return out;
}

}  // namespace feeddrive::fit
