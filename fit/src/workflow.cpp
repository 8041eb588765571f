#include "feeddrive/fit/workflow.hpp"
#include "text.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <optional>

namespace feeddrive::fit {
using text::fmt;
using text::par;

namespace {

double bic_of(double rss, int k, long n) {
  const double nn = static_cast<double>(n);
  return nn * std::log(std::max(rss, 1e-300) / nn) + k * std::log(nn);
}

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

Effect effect_of(const plant::PlantParams& p, const std::string& name) {
  for (const Effect& e : plant::enabled_effects(p.effects))
    if (e.name == name) return e;
  return {name, {}};
}

// Out-of-sample check of adding an effect (the one-standard-error rule: Breiman, Friedman, Olshen
// & Stone 1984; Hastie, Tibshirani & Friedman 2009, sec. 7.10): the mean per-block reduction of
// the held-out squared residual must exceed its standard error over the blocks.
struct CvVerdict {
  bool confirmed{false};
  double mean{0.0}, se{0.0};
};
CvVerdict cv_verdict(const std::vector<double>& without, const std::vector<double>& with) {
  const double K = static_cast<double>(without.size());
  std::vector<double> d(without.size());
  for (std::size_t k = 0; k < d.size(); ++k) d[k] = without[k] - with[k];
  CvVerdict v;
  v.mean = std::accumulate(d.begin(), d.end(), 0.0) / K;
  double ss = 0.0;
  for (double x : d) ss += (x - v.mean) * (x - v.mean);
  v.se = K > 1 ? std::sqrt(ss / (K - 1) / K) : 0.0;
  v.confirmed = v.mean > 0.0 && v.mean > v.se;
  return v;
}

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

}  // namespace

void check_options(const Record& rec, const FitOptions& opt) {
  // A replay window must hold more samples than the two its start-state correction fits
  // (offset and slope): a window of 2 or 3 samples replays any model with a gap of 0.
  if (opt.replay_window > 0 && opt.replay_window < 10.0 * rec.period)
    throw DataError(rec.data->source +
                    fmt(": --replay-window %.3g s spans fewer than 10 sample periods (%.3g s) of the "
                        "record; use at least %.3g s, or 0 for the default",
                        opt.replay_window, rec.period, 10.0 * rec.period));
}

FitResult run_fit(const Record& rec_in, const plant::PlantParams& model, const FitOptions& opt, const Log& log) {
  check_options(rec_in, opt);
  Record rec = rec_in;
  mask_stiction(rec, model);
  const long n = rec.active_points();
  const auto say = [&](const std::string& s) {
    if (log) log(s);
  };
  FitResult out;
  out.initial = model;
  out.envelope = envelope(rec, model);
  out.smoothing_initial = model.friction.static_smoothing_velocity;
  out.shape_initial = model.friction.static_smoothing_shape;
  // The effects added so far. The model-form parameter eps is refitted with them at the start and
  // after every addition (recalibrate), and held in the many candidate, cross-validation and
  // backward fits between: with a static friction model every change of eps recomputes the
  // friction along the whole record.
  FreeSet free{{}, false};
  plant::PlantParams current = model;
  const auto recalibrate = [&](const plant::PlantParams& p) {
    if (!opt.fit_form) return p;
    FreeSet f{free.effects, true, 0.0};
    // a friction's direction asymmetry, carried as a bounded constant force (model form)
    if (!contains(free.effects, "constant_force") && !p.effects.spring_force.enabled)
      f.offset_bound = kAsymmetryTolerance * friction_level(p);
    if (!has_coulomb_term(p) && f.offset_bound == 0.0) return p;
    plant::PlantParams q = fit_jointly(rec, p, f, nullptr, 200, opt.stop).params;
    try {
      q.validate();
    } catch (const std::invalid_argument&) {
      return p;
    }
    return q;
  };
  // 0. Model form: a static friction's transition velocity is fitted before anything is added.
  current = recalibrate(current);
  Eigen::VectorXd r = force_residual(rec, current);
  double cur_bic = bic_of(r.squaredNorm(), free.parameters(current), n);
  Replay rp = replay(rec, current, opt.replay_window, opt.stop);
  out.replay_initial = replay(rec, model, opt.replay_window, opt.stop);
  out.force_rms_initial = rms(force_residual(rec, model), n);
  if (!std::isfinite(out.replay_initial.gap) || !std::isfinite(out.force_rms_initial)) {
    // Finite samples whose squares are not (a position outlier of 1e200 m): no finite metric.
    const MeasuredData& d = *rec.data;
    std::size_t worst = 0;
    for (std::size_t k = 0; k < d.size(); ++k)
      if (std::abs(d.x[k]) > std::abs(d.x[worst])) worst = k;
    throw DataError(d.source +
                    fmt(": the replay gap or the force residual of the model is not finite on this record (its "
                        "largest position is %.6g m at t = %.6g s): is the position column in metres and free of "
                        "outliers?",
                        d.x[worst], d.t[worst]));
  }
  say("initial model: gap " +
      fmt("%.4g um, force residual RMS %.4g N", out.replay_initial.gap * 1e6, out.force_rms_initial));
  std::vector<std::string> added;  // in the order found; removed ones are taken out
  // A ripple whose fitted pitch fails a resolvability limit only by its uncertainty: the caveat
  // (named as tentative: docs/fit.md, "Tentative effects").
  constexpr double kPitchMargin = 0.05;
  // (empty if e is no such case). The 95 % interval is that of the joint fit of `effects`.
  const Envelope& env = out.envelope;
  const auto borderline = [&](const plant::PlantParams& p, const std::vector<std::string>& effects,
                              const Effect& e) -> std::string {
    if (e.name != "cogging_ripple" && e.name != "reluctance_ripple") return "";
    const double pitch = e.parameters.at("pitch_m");
    if (pitch <= env.max_pitch() && pitch >= env.min_pitch()) return "";  // another limit failed
    const double limit = pitch > env.max_pitch() ? env.max_pitch() : env.min_pitch();
    const auto ci = confidence_intervals(rec, p, effects);
    const double w = ci.count(e.name) && ci.at(e.name).count("pitch_m") ? ci.at(e.name).at("pitch_m") : 0.0;
    // Within the 95 % interval, or within kPitchMargin of the limit: the limits (two periods in
    // the travel, four filter half-widths per period) are rules of thumb of resolvability, not
    // physical bounds; a pitch seen over 1.9 periods is resolved nearly as well as over 2.
    if (!(std::abs(pitch - limit) <= std::max(w, kPitchMargin * limit))) return "";
    return fmt("tentative: the fitted pitch %.4g +- %.2g mm (95 %%) is within %.2g %% of the limit %.4g mm",
               pitch * 1e3, w * 1e3, 100 * std::abs(pitch - limit) / limit, limit * 1e3) +
           fmt("; record a travel of at least 3 periods (%.3g mm) to confirm it", 3e3 * pitch);
  };
  // The simpler effect a refit may turn an effect into (the swap move), if any.
  const double x_mean = mean_position(rec);
  const auto simpler = [&](const Effect& e) { return simpler_form(e, x_mean); };
  std::map<std::string, std::string> tentative;  // effect -> caveat, of the effects named as tentative
  int additions = 0;
  for (int it = 0; additions < opt.max_effects && it < 2 * opt.max_effects + 2; ++it) {
    // Polish: the effects already in are refitted to convergence first, so that no candidate's
    // joint fit gets credit for merely finishing the optimisation of the others.
    if (!free.effects.empty()) {
      const JointFit polished = fit_jointly(rec, current, free, nullptr, 200, opt.stop);
      if (polished.rss < r.squaredNorm()) {
        current = polished.params;
        r = force_residual(rec, current);
        cur_bic = bic_of(r.squaredNorm(), free.parameters(current), n);
      }
    }
    StepResult st;
    st.localisation = localise(rec, r, rp);
    st.gap_before = rp.gap;
    st.force_rms_before = rms(r, n);
    st.residual_before = r;
    // 1. forward: every candidate, fitted alone (the start) and then jointly
    for (const std::string& name : plant::effect_names()) {
      if (contains(free.effects, name)) continue;
      CandidateFit c;
      c.effect = {name, {}};
      c.score = -std::numeric_limits<double>::infinity();
      // the prerequisites see the named effects: a model-form offset carried by constant_force
      // is no constant force that would rule out a spring
      plant::PlantParams named = current;
      if (!contains(free.effects, "constant_force")) named.effects.constant_force.enabled = false;
      c.passed_over = prerequisite(out.envelope, named, name, opt.plausibility);
      if (!c.passed_over.empty()) {
        c.reason = Reason::kPrerequisite;
        st.ranking.push_back(c);
        continue;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const CandidateFit single = fit_candidate(rec, current, name, r, opt.stop);
      plant::PlantParams trial = current;
      plant::set_effect(trial.effects, single.effect);
      FreeSet fs = free;
      fs.effects.push_back(name);
      // A Coulomb-type candidate on a model without static friction brings its own transition
      // velocity: eps is fitted with it (cheap: no friction along the record is recomputed).
      fs.form = opt.fit_form && current.friction.model != plant::FrictionModel::kStatic &&
                (name == "coulomb_friction" || name == "stribeck_friction");
      // the single fit is a good start: the joint fit converges in a few tens of iterations
      JointFit jf = fit_jointly(rec, trial, fs, nullptr, 40, opt.stop);
      const Effect canon = canonical(effect_of(jf.params, name));
      if (canon.parameters != effect_of(jf.params, name).parameters) {
        plant::PlantParams p = jf.params;
        plant::set_effect(p.effects, canon);
        const JointFit jc = fit_jointly(rec, p, fs, nullptr, 40, opt.stop);
        // the canonical form has two parameters fewer in effect; keep it unless the BIC says otherwise
        if (bic_of(jc.rss, fs.parameters(jc.params) - 2, n) <= bic_of(jf.rss, fs.parameters(jf.params), n)) jf = jc;
      }
      // Plausibility of every refitted effect, with two moves before a candidate is passed over:
      //  * tentative: the candidate fails a resolvability limit of its pitch only by the
      //    uncertainty of its fitted value (the limit within the 95 % interval): it is named
      //    with the caveat, and the other effects are then judged with it in the model;
      //  * swap: the refit turned an effect already in the model into a simpler one (a Stribeck
      //    curve without a hump is Coulomb friction, a spring without a slope a constant force,
      //    a ripple whose fundamental vanished its harmonic): it is replaced and refitted.
      try {
        jf.params.validate();
      } catch (const std::invalid_argument& e) {
        c.passed_over = std::string("fitted to invalid values (") + e.what() + ")";
        c.reason = Reason::kInvalid;
      }
      for (int pass = 0; pass < 2 && c.passed_over.empty(); ++pass) {
        std::string swap_from;
        for (const Effect& e : plant::enabled_effects(jf.params.effects)) {
          if (!contains(fs.effects, e.name)) continue;  // the model's own, or model form (asymmetry offset)
          const std::string why = implausible(out.envelope, jf.params, e);
          if (why.empty()) continue;
          if (const std::string cav = borderline(jf.params, fs.effects, e); !cav.empty()) {
            if (e.name == name) {
              c.tentative = true;
              c.caveat = why + "; " + cav;
            }
            continue;
          }
          if (e.name != name && pass == 0 && simpler(e).has_value()) {
            swap_from = e.name;
            break;
          }
          c.passed_over = e.name == name ? why : "refitted with it, " + e.name + " becomes implausible: " + why;
          c.reason = Reason::kImplausible;
          break;
        }
        if (swap_from.empty()) break;
        // the swap move: replace the collapsed effect by its simpler form and refit jointly
        const Effect simple = *simpler(effect_of(jf.params, swap_from));
        plant::PlantParams p = jf.params;
        plant::effect_enabled(p.effects, swap_from) = false;
        FreeSet fs2 = fs;
        fs2.effects.erase(std::find(fs2.effects.begin(), fs2.effects.end(), swap_from));
        if (contains(fs2.effects, simple.name)) {  // e.g. a spring that became the candidate constant force
          Effect merged = effect_of(p, simple.name);
          for (auto& [k, v] : merged.parameters) v += simple.parameters.at(k);
          plant::set_effect(p.effects, merged);
        } else {
          plant::set_effect(p.effects, simple);
          fs2.effects.push_back(simple.name);
        }
        const JointFit js = fit_jointly(rec, p, fs2, nullptr, 60, opt.stop);
        try {
          js.params.validate();
        } catch (const std::invalid_argument&) {
          c.passed_over = "refitted with it, " + swap_from + " collapses, and its simpler form cannot be fitted";
          c.reason = Reason::kImplausible;
          break;
        }
        c.swap = swap_from + (simple.name == swap_from ? " (its fundamental vanished: its harmonic)" : "") + " -> " +
                 simple.name;
        jf = js;
        fs = fs2;
      }
      c.effect = effect_of(jf.params, name);
      c.joint = jf.params;
      c.rss = jf.rss;
      c.converged = jf.converged;
      c.free_effects = fs.effects;
      fs.form = false;  // eps is a model-form parameter, counted in no score (it is fitted for every model alike)
      c.parameters = fs.parameters(jf.params) - free.parameters(current);
      c.bic = bic_of(jf.rss, fs.parameters(jf.params), n);
      c.score = cur_bic - c.bic;
      if (!std::isfinite(c.score)) c.score = -std::numeric_limits<double>::infinity();
      c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      st.ranking.push_back(c);
    }
    std::stable_sort(st.ranking.begin(), st.ranking.end(),
                     [](const CandidateFit& a, const CandidateFit& b) { return a.score > b.score; });
    // Parsimony: an eligible candidate within kParsimony of the best eligible score is not
    // distinguishable from it (a BIC difference below 10 is not "very strong" evidence, Kass &
    // Raftery 1995); among those the one with the fewest parameters goes first.
    {
      constexpr double kParsimony = 10.0;
      std::vector<std::size_t> eligible;
      for (std::size_t i = 0; i < st.ranking.size(); ++i)
        if (st.ranking[i].passed_over.empty()) eligible.push_back(i);
      if (!eligible.empty()) {
        const double top = st.ranking[eligible.front()].score;
        std::size_t pick = eligible.front();
        for (std::size_t i : eligible)
          if (st.ranking[i].score >= top - kParsimony && st.ranking[i].parameters < st.ranking[pick].parameters)
            pick = i;
        const auto first = st.ranking.begin() + static_cast<long>(eligible.front());
        std::rotate(first, st.ranking.begin() + static_cast<long>(pick),
                    st.ranking.begin() + static_cast<long>(pick) + 1);
      }
    }
    // 2. the best eligible candidate that is significant, confirmed out of sample and by the replay
    std::vector<double> cv_without;
    const CandidateFit* chosen = nullptr;
    FreeSet chosen_free;
    Replay rp2;
    std::string why_not;
    // Close calls: BIC scores within kCloseCall of the best eligible one are decided out of
    // sample, by the lower held-out squared residual (e.g. a reluctance ripple against a mass
    // error, both proportional to the thrust while it accelerates).
    constexpr double kCloseCall = 50.0;
    std::map<std::string, std::vector<double>> cv_cache;
    const auto cv_of = [&](const CandidateFit& c) -> const std::vector<double>& {
      auto it = cv_cache.find(c.effect.name);
      if (it != cv_cache.end()) return it->second;
      FreeSet fs = free;
      fs.effects = c.free_effects;
      return cv_cache[c.effect.name] = cross_validate(rec, c.joint, fs, opt.cv_folds, opt.stop);
    };
    {
      std::vector<std::size_t> close;
      for (std::size_t i = 0; i < st.ranking.size(); ++i) {
        const CandidateFit& c = st.ranking[i];
        if (!c.passed_over.empty() || !(c.score >= opt.score_threshold)) continue;
        if (!close.empty() && c.score < st.ranking[close.front()].score - kCloseCall) break;
        if (close.size() < 3) close.push_back(i);
      }
      if (close.size() > 1) {
        // the one-standard-error rule in its original form: the lowest held-out error, unless
        // a candidate with fewer parameters is within one standard error of it
        std::size_t best = close.front();
        for (std::size_t i : close)
          if (total(cv_of(st.ranking[i])) < total(cv_of(st.ranking[best]))) best = i;
        std::size_t pick = best;
        for (std::size_t i : close) {
          if (st.ranking[i].parameters >= st.ranking[pick].parameters) continue;
          const CvVerdict v = cv_verdict(cv_of(st.ranking[i]), cv_of(st.ranking[best]));
          if (v.mean <= v.se) pick = i;
        }
        std::vector<CandidateFit> picked;
        picked.push_back(st.ranking[pick]);
        for (std::size_t i : close)
          if (i != pick) picked.push_back(st.ranking[i]);
        for (std::size_t k = 0; k < close.size(); ++k) st.ranking[close[k]] = picked[k];
      }
    }
    for (CandidateFit& c : st.ranking) {
      if (!c.passed_over.empty()) continue;
      if (!(c.score >= opt.score_threshold)) {
        c.reason = Reason::kBelowThreshold;
        continue;
      }
      if (cv_without.empty()) cv_without = cross_validate(rec, current, free, opt.cv_folds, opt.stop);
      const std::vector<double> cv_with = cv_of(c);
      const CvVerdict v = cv_verdict(cv_without, cv_with);
      if (!v.confirmed) {
        c.passed_over =
            fmt("not confirmed out of sample: held-out squared residual %.4g -> %.4g N^2 "
                "(mean reduction per block %.3g, standard error %.3g)",
                total(cv_without), total(cv_with), v.mean, v.se);
        c.reason = Reason::kNotConfirmed;
        why_not += (why_not.empty() ? "" : "; ") + c.effect.name + " " + c.passed_over;
        continue;
      }
      try {
        rp2 = replay(rec, c.joint, opt.replay_window, opt.stop);
      } catch (const std::exception& e) {  // e.g. CVODE cannot integrate the fitted model
        c.passed_over = std::string("cannot be replayed (") + e.what() + ")";
        c.reason = Reason::kInvalid;
        why_not += (why_not.empty() ? "" : "; ") + c.effect.name + " " + c.passed_over;
        continue;
      }
      if (!(rp2.gap <= (1.0 - opt.min_gap_reduction) * rp.gap)) {
        c.passed_over = fmt("does not shrink the replay gap by %.3g %% (%.4g -> %.4g um)", 100 * opt.min_gap_reduction,
                            rp.gap * 1e6, rp2.gap * 1e6);
        c.reason = Reason::kNoGapReduction;
        why_not += (why_not.empty() ? "" : "; ") + c.effect.name + " " + c.passed_over;
        continue;
      }
      st.cv_without = cv_without;
      st.cv_with = cv_with;
      chosen = &c;
      chosen_free = free;
      chosen_free.effects = c.free_effects;
      break;
    }
    if (!chosen) {
      const CandidateFit* best = nullptr;
      for (const CandidateFit& c : st.ranking)
        if (!best && std::isfinite(c.score)) best = &c;
      st.verdict = best ? "no significant effect: the best candidate, " + best->effect.name +
                              fmt(", scores %.3g (threshold %.3g)", best->score, opt.score_threshold)
                        : std::string("no significant effect: no candidate is eligible");
      if (!why_not.empty()) st.verdict += "; passed over: " + why_not;
      st.gap_after = st.gap_before;
      st.force_rms_after = st.force_rms_before;
      st.residual_after = r;
      say(st.verdict);
      out.steps.push_back(st);
      break;
    }
    st.accepted = true;
    st.effect = chosen->effect;
    st.score = chosen->score;
    st.swap = chosen->swap;
    if (chosen->tentative) st.caveat = chosen->caveat;
    // Ties: another significant candidate that explains the data as well (its score within the
    // threshold of the winner's) or the same way (its fitted force nearly collinear with the
    // winner's: |cos| >= 0.98 between the two changes of the filtered residual).
    {
      const Eigen::VectorXd d0 = r - force_residual(rec, chosen->joint);
      for (const CandidateFit& o : st.ranking) {
        if (&o == chosen || !(o.score >= opt.score_threshold)) continue;
        if (o.reason != Reason::kNone && o.reason != Reason::kNotConfirmed && o.reason != Reason::kNoGapReduction)
          continue;
        const Eigen::VectorXd d1 = r - force_residual(rec, o.joint);
        const double cosine = d0.dot(d1) / std::max(d0.norm() * d1.norm(), 1e-300);
        if (std::abs(chosen->score - o.score) <= opt.score_threshold || std::abs(cosine) >= 0.98) {
          st.ties.push_back(o.effect.name);
          st.tie_notes.push_back(fmt("%.4g", o.score) + " against " + fmt("%.4g", chosen->score) +
                                 fmt(", fitted forces collinear to %.3f", cosine));
        }
      }
    }
    const std::string name = chosen->effect.name;
    free = chosen_free;
    current = recalibrate(chosen->joint);
    if (!chosen->swap.empty()) {  // the swap move: the collapsed effect leaves, its simpler form comes in
      const std::string from = chosen->swap.substr(0, chosen->swap.find(' '));
      std::replace(added.begin(), added.end(), from, std::string("\x01"));
      added.erase(std::remove(added.begin(), added.end(), std::string("\x01")), added.end());
      tentative.erase(from);
      for (const std::string& e : free.effects)
        if (e != name && !contains(added, e)) added.push_back(e);
      say("swap: " + chosen->swap + " (refitted with " + name + ")");
    }
    if (chosen->tentative) tentative[name] = chosen->caveat;
    added.push_back(name);
    ++additions;
    r = force_residual(rec, current);
    cur_bic = bic_of(r.squaredNorm(), free.parameters(current), n);
    try {
      rp = replay(rec, current, opt.replay_window, opt.stop);
    } catch (const std::exception&) {  // the recalibrated model cannot be replayed: keep the candidate's
      current = chosen->joint;
      r = force_residual(rec, current);
      cur_bic = bic_of(r.squaredNorm(), free.parameters(current), n);
      rp = rp2;
    }
    st.verdict =
        "added " + name + fmt(" (score %.4g): gap %.4g -> %.4g um", st.score, st.gap_before * 1e6, rp.gap * 1e6);
    if (!why_not.empty()) st.verdict += " (passed over: " + why_not + ")";
    say(st.verdict);
    // 3. backward: remove the earlier effect that costs least, while it costs less than the threshold
    for (;;) {
      std::string drop;
      JointFit best_without;
      double least = opt.score_threshold;
      for (const std::string& e : free.effects) {
        if (e == name) continue;
        FreeSet fr = free;
        fr.effects.erase(std::find(fr.effects.begin(), fr.effects.end(), e));
        plant::PlantParams p = current;
        plant::effect_enabled(p.effects, e) = false;
        const JointFit jf = fit_jointly(rec, p, fr, nullptr, 100, opt.stop);
        const double loss = bic_of(jf.rss, fr.parameters(jf.params), n) - cur_bic;
        if (loss < least) {
          least = loss;
          drop = e;
          best_without = jf;
        }
      }
      if (drop.empty()) break;
      Replay rp_without;
      try {
        best_without.params.validate();
        rp_without = replay(rec, best_without.params, opt.replay_window, opt.stop);
      } catch (const std::exception&) {  // the model without it cannot be replayed: keep it
        break;
      }
      current = best_without.params;
      free.effects.erase(std::find(free.effects.begin(), free.effects.end(), drop));
      added.erase(std::find(added.begin(), added.end(), drop));
      r = force_residual(rec, current);
      cur_bic = bic_of(r.squaredNorm(), free.parameters(current), n);
      rp = rp_without;
      st.removed.push_back(drop);
      const std::string line = "removed " + drop + ": with " + name + " in," +
                               fmt(" it is worth only %.3g in BIC; gap now %.4g um", least, rp.gap * 1e6);
      st.verdict += "; " + line;
      say(line);
    }
    st.gap_after = rp.gap;
    st.force_rms_after = rms(r, n);
    st.residual_after = r;
    out.steps.push_back(st);
  }
  // eps means nothing to a model without a Coulomb-type term (e.g. once presliding made it LuGre)
  if (!has_coulomb_term(current)) {
    current.friction.static_smoothing_velocity = model.friction.static_smoothing_velocity;
    current.friction.static_smoothing_shape = model.friction.static_smoothing_shape;
  }
  if (current.effects.constant_force.enabled && !contains(added, "constant_force"))
    out.asymmetry_offset = current.effects.constant_force.force_N;
  out.fitted = current;
  out.smoothing_final = current.friction.static_smoothing_velocity;
  out.shape_final = current.friction.static_smoothing_shape;
  out.smoothing_fitted = out.smoothing_final != out.smoothing_initial || out.shape_final != out.shape_initial;
  out.replay_final = rp;
  out.force_rms_final = rms(r, n);
  out.final_localisation = localise(rec, r, rp);
  for (const std::string& name : added) out.effects.push_back(effect_of(current, name));
  out.ci95 = confidence_intervals(rec, current, added);
  for (const auto& [name, caveat] : tentative)
    if (contains(added, name)) out.tentative[name] = caveat;
  // ties that no later step resolved (the other candidate was not named after all)
  for (const StepResult& st : out.steps) {
    if (!st.accepted || !contains(added, st.effect.name)) continue;
    for (std::size_t i = 0; i < st.ties.size(); ++i) {
      if (contains(added, st.ties[i])) continue;
      out.ties.push_back(
          st.effect.name + " or " + st.ties[i] + " (scores " + st.tie_notes[i] +
          "): the record cannot separate them; what would: " + what_would_separate(st.effect.name, st.ties[i]));
    }
  }
  // The verdict against the sensor's noise floor (verdict.hpp).
  out.floor = noise_floor(rec, model, FloorOptions{opt.stamp_error, opt.replay_window});
  const double gap_final = rp.gap, force_final = out.force_rms_final;
  const bool final_within = within_floor(out.floor, gap_final, force_final);
  const std::string floor_text = fmt("the noise floor (gap %.3g um, force residual %.3g N RMS; within = at most %.0fx)",
                                     out.floor.gap * 1e6, out.floor.force, kFloorFactor);
  if (added.empty() && final_within) {
    out.verdict = Verdict::kNoDiscrepancy;
    out.conclusion = "no discrepancy: the model explains the data to within its noise: gap " +
                     fmt("%.4g um, force residual %.4g N RMS, within ", gap_final * 1e6, force_final) + floor_text;
  } else if (final_within) {
    out.verdict = Verdict::kExplained;
    out.conclusion = "explained: found " + std::to_string(added.size()) + " effect(s):";
    for (const auto& e : added) out.conclusion += " " + e + (out.tentative.count(e) ? " (tentative)" : "");
    out.conclusion += fmt("; gap %.4g -> %.4g um, force residual %.4g N RMS, within ", out.replay_initial.gap * 1e6,
                          gap_final * 1e6, force_final) +
                      floor_text;
  } else {
    out.verdict = Verdict::kUnexplained;
    out.conclusion = "unexplained discrepancy: " +
                     fmt("gap %.4g um and force residual %.4g N RMS stay above ", gap_final * 1e6, force_final) +
                     floor_text;
    if (!added.empty()) {
      out.conclusion += "; named:";
      for (const auto& e : added) out.conclusion += " " + e + (out.tentative.count(e) ? " (tentative)" : "");
      out.conclusion +=
          fmt(" (gap %.4g -> %.4g um), and the rest is not named", out.replay_initial.gap * 1e6, gap_final * 1e6);
    } else {
      out.conclusion += "; no candidate could be named with confidence";
    }
    // where, what it resembles, why not, what would settle it
    out.unexplained.push_back("where: " + out.final_localisation.summary);
    const StepResult* last = out.steps.empty() ? nullptr : &out.steps.back();
    if (!last || last->accepted) {
      out.unexplained.push_back(
          fmt("the search stopped at --max-effects %.0f: allow more effects to go on", opt.max_effects));
    } else {
      int shown = 0;
      for (const CandidateFit& c : last->ranking) {
        if (shown >= 3) break;
        const bool resembles = std::isfinite(c.score) && c.score > 0.0;
        const bool prerequisite_ripple = c.reason == Reason::kPrerequisite &&
                                         (c.effect.name == "cogging_ripple" || c.effect.name == "reluctance_ripple");
        if (!resembles && !prerequisite_ripple) continue;
        ++shown;
        std::string why = c.passed_over;
        if (why.empty() && c.reason == Reason::kBelowThreshold)
          why = fmt("its score %.3g is below the threshold %.3g", c.score, opt.score_threshold);
        if (why.empty()) why = "not reached";
        std::string line = "resembles " + c.effect.name;
        if (resembles) line += fmt(" (score %.4g)", c.score);
        if (c.effect.name == "cogging_ripple" || c.effect.name == "reluctance_ripple") {
          const auto it = c.effect.parameters.find("pitch_m");
          if (it != c.effect.parameters.end()) line += fmt(", pitch %.4g mm", it->second * 1e3);
        }
        line += "; not named: " + why;
        std::string settle = what_would_settle(env, c, c.reason);
        if (c.passed_over.rfind("refitted with it, ", 0) == 0) {  // what settles the effect it makes implausible
          const std::string other = c.passed_over.substr(18, c.passed_over.find(' ', 18) - 18);
          CandidateFit o = c;
          o.effect = effect_of(c.joint, other);
          if (!o.effect.parameters.empty()) settle = what_would_settle(env, o, Reason::kImplausible);
        }
        if (!settle.empty()) line += "; to settle it: " + settle;
        out.unexplained.push_back(line);
      }
      if (shown == 0) {
        // no candidate resembles it: say where to look, by the regime where the rest concentrates
        const Bin* where = nullptr;
        for (const Bin& b : out.final_localisation.velocity)
          if (b.points >= 3 && (!where || b.concentration > where->concentration)) where = &b;
        const std::string regime = where ? where->label : std::string("the record");
        out.unexplained.push_back(
            "no candidate of the vocabulary reduces the residual: an effect outside the vocabulary (e.g. the form of "
            "the "
            "friction's transition), or a sensor noisier than plant.sensor says (" +
            out.floor.source + "); to settle it: record more of the regime where the rest concentrates (" + regime +
            ": e.g. slow reversals and creeping moves for friction at low speed), and measure the sensor at rest for "
            "its "
            "noise");
      }
    }
    if (!out.floor.from_scenario) out.unexplained.push_back("noise floor: " + out.floor.source);
  }
  if (out.asymmetry_offset != 0.0)
    out.conclusion +=
        fmt("; model form: friction direction asymmetry %.3g N (carried as constant_force)", out.asymmetry_offset);
  if (out.smoothing_fitted)
    out.conclusion +=
        fmt("; model form: Coulomb transition velocity %.3g -> %.3g mm/s, shape %.2g -> %.2g (0 tanh, 1 algebraic)",
            out.smoothing_initial * 1e3, out.smoothing_final * 1e3, out.shape_initial, out.shape_final);
  say(out.conclusion);
  return out;
}

}  // namespace feeddrive::fit
