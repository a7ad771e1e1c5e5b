"""Xu, Oliveira & Guedes Soares (2021) §5: L1 adaptive backstepping in a two-phase current.

The experiment: the ``osaka_stochastic_current`` scenario (Esso Osaka 1:100 at 0.41 m/s
from the origin at ψ0 = 26° along the paper's seven waypoints, TVVF guidance eq. (48),
current towards 180° about 0.1 m/s, then about 0.2 m/s from half the time limit, i.e. from
t = 1000 s; the paper gives neither the switch time nor the fluctuation, see
:mod:`shipgym.disturbances`) under four controllers:

* ``l1_backstepping`` — the paper's L1 controller, C(s) of eq. (39) on the whole command
  (:mod:`shipgym_baselines.classical.l1_backstepping`, §5.2 gains, ω = 0.25 rad/s, ζ = 1);
* ``l1_backstepping_adaptive_filter`` — the same with C(s) only on the estimates' share of
  the command (``filter_placement="adaptive"``, the standard L1 structure u = u_nom +
  C(s)·u_ad; our alternative reading of Fig. 4 / eq. (39));
* ``adaptive_backstepping`` — filter off ("a typical adaptive backstepping controller");
* ``pid_tvvf`` — the §5.2 PID baseline: pole placement Kp = ωn²T/K, Kd = (2ζωnT − 1)/K,
  Ki = ωn³T/(10K), ωn = 1 rad/s, ζ = 1, on the same TVVF law (as registered: without the
  drift-angle term −β of eq. (48)).

The paper prints no numbers for its runs, only figures (Figs. 9–15) and what it reads from
them.  Rows (``case, controller, metric, ours, paper``, ``seeds``, ``ours_std``) hold:

* per current phase (``weak_current`` t < t_switch, ``strong_current`` t ≥ t_switch) and
  for the whole ``episode``, per controller: ACE = mean |e| and the |e| spread and maximum;
  the heading error to the path (the leaderboard's ψ̃) and to the controller's own reference
  ψ − ψd; the rudder angle (mean |δ|, RMS, mean |δ̇|); the RMS above ω = 0.25 rad/s (the
  filter corner) and above 1 rad/s of the rudder *command* and of the rudder *angle*
  (Welch PSD, :func:`~shipgym_baselines.classical.l1_backstepping.high_frequency_power`, the figure
  the controllers' ``episode_stats`` report); the drift angle over ground (course −
  heading, the paper's β with earth-fixed u, v) spread and HF RMS; the settling after each
  waypoint switch (time until |e| stays below the leaderboard's convergence threshold
  0.05·L/0.95 up to the next switch: mean, ∞ if one never does; share of switches that
  settle; mean over those that do); the HF RMS of the bias estimate b̂ and, for the whole
  episode, the final estimates and the predictor's mean |r̂ − r| (L1 variants).  All
  ``paper = None`` (no published number);
* ``claims``: each qualitative statement of §5.2 evaluated on the whole-episode means: a
  comparison holds when ours is at least ``CLAIM_MARGIN`` = 10 % lower (the ``ratio`` is in
  the row); "cross-track errors nearly same" is the ACE ratio against the paper's 1.0;
* ``linearised``: the law (35) with exact estimates on its design model, linearised at
  r = 0 (:func:`~shipgym_baselines.classical.adaptive.loop_analysis.linearised_closed_loop_poles`):
  the
  largest closed-loop pole real part and the loop's crossover and phase margin, against
  the paper's UGAS claim (§3–4) as "stable: True".  Continuous time: the 0.5-s sampling
  (≈ 27° more lag at 1.9 rad/s) and the rudder servo are left out.

Episode metrics come from :func:`shipgym_baselines.evaluation.run_episode` (the leaderboard's);
per-phase figures are computed from the same trajectory (rows after the reset sample, as
:func:`shipgym.metrics.compute_metrics` counts them), so the ``episode`` ACE equals the
leaderboard's ``ace``.  Seeds are ``EVAL_SEED_OFFSET + i``; ``ours`` is the mean over
seeds, ``ours_std`` the population spread.  Writes ``xu2021.md`` / ``.json`` and
``xu2021.png`` (tracks, current speed, e(t), ψ − ψd, δ(t) and δc(t) per controller, the
command spectra and b̂(t), first seed).

Welch's estimate drops the samples after the last full 128-s segment and under-weights the
first and last 32 s (Hann taper); on the full runs it agrees within ≈ 10 % with a zero-phase
high-pass RMS and a full-length periodogram, except the PID's start-up burst (0.25-rad/s
band 2.2° against 2.5–3.0°).  Orderings between controllers are the same with all three.

Findings (3 seeds, ``shipgym reproduce xu2021 --seeds 3``), each gap from the model:

* ``l1_backstepping`` (eq. (39) as printed) is linearly unstable: eq. (35) with K2 = 15 is
  a PD law with Kd ≈ 75 s on K/(s(Ts + 1)), K = 0.189 1/s, T = 7.37 s, crossing over at
  1.9 rad/s; C(s) in series (corner 0.25 rad/s) moves the crossover to 0.45 rad/s with a
  phase margin of −26°.  The rudder settles into a saturated limit cycle (±30–35°, period
  ≈ 43 s), so ACE is 4.6× the unfiltered law's, the drift-angle spread, b̂'s HF content and
  the rudder rate 4–5× — against Figs. 10–14.  What the filter is for holds: the command's
  RMS above 1 rad/s is 13× lower and above 0.25 rad/s 18 % lower; the rudder angle's
  0.25-band RMS is not lower (the limit cycle's harmonics sit in it).
* ``l1_backstepping_adaptive_filter`` equals ``adaptive_backstepping`` (every ratio
  0.97–1.00): the design model comes from the ship's own zig-zag, so the estimates stay
  within 0.5 % of nominal and the filtered share of the command is ≈ 0.  The rudder's HF
  content in ``adaptive_backstepping`` is not adaptation noise but the high-gain law's
  hard-over bursts at the waypoint switches (ψd steps with the path angle), which belong to
  the nominal law.  The paper's HF in δ and b̂ (Figs. 12, 14) needs adaptation transients
  this plant / design-model pair does not produce.
* ``pid_tvvf``: without −β its TVVF reference balances the crab angle of a cross current
  with a standing offset (0.1–0.75 m on the legs oblique to the current), so only half of
  the switches settle; those that do settle faster (≈ 40 s) than the backstepping laws
  (≈ 64 s, outer gain K1 = 0.02 1/s).  "L1 better than PID" (Fig. 15) holds for the stable
  readings (ACE 0.58×), not for the printed one (2.65×).

Parts (:mod:`shipgym_baselines.reproduce.protocol`): :mod:`.scenario` (the two-phase current),
:mod:`.controllers` (the four laws, recorded), :mod:`.metrics` (one episode's figures per
phase), :mod:`.linearised` (the loop at r = 0), :mod:`.claims` (§5.2's statements),
:mod:`.experiment` (the runs and rows), :mod:`.current` (the true current from the env's
log), :mod:`.tables` (the markdown), :mod:`.figures` (the plots).
"""

from shipgym_baselines.reproduce.protocol import Reproduction
from shipgym_baselines.reproduce.xu2021.experiment import run_experiment
from shipgym_baselines.reproduce.xu2021.figures import plots
from shipgym_baselines.reproduce.xu2021.tables import report

REPRODUCTION = Reproduction("xu2021", run_experiment, report, plots)
