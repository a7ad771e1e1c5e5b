"""Xu & Guedes Soares (2020) §5–§6: Esso Osaka, look-ahead LOS vs VF with a Vyshnegradsky PID.

The experiment, on the ``esso_osaka`` plant (1:100 model, L = 3.25 m, U0 = 0.41 m/s):

1. §5.2: a 20/20 zig-zag and the LS-SVM fit (linear kernel, C = 2544) of the 2nd-order
   Nomoto model (:func:`shipgym.identification.zigzag.ship_nomoto`, the pipeline every
   model-based controller uses), against the paper's K = 0.185 1/s, T1 = 7.8569 s,
   T2 = 0.3815 s, T3 = 0.5297 s — model-scale units on both sides (the paper's ship is the
   3.4 m model at 0.41 m/s); and the PID gains of the Vyshnegradsky diagram from our fit,
   A = B = 4 (stated, §5.1) and A = B = 3 (the reading that reproduces the printed
   "212.6 and 547.8" as Kd, Kp, :mod:`shipgym.autopilot`), Ki = Kp/100;
2. §6.1 (``straight``, Table 2): four waypoints joined by straight legs, start at the origin
   with heading 0 at 0.41 m/s;
3. §6.2 (``curved``, Table 3): the same waypoints joined by the PCHIP curve (the catalogue's
   ``osaka_curved``), start at the origin with heading 0 and, as the paper states, an
   initial speed of 0.1 m/s (``curved_initial_speed``; the speed controller then brings it
   to 0.41 m/s; ``None`` starts at cruise speed);

each under ``pid_lookahead_los`` (eq. (6), Δ = 2L) and ``pid_vf`` (Algorithm 1, τ = 2L,
χe = 90°, k = 1) of :mod:`shipgym_baselines.classical.pid`, both with the Vyshnegradsky gains.

The paper's Figure 8 (the waypoints) is lost: both cases use ``osaka_curved``'s assumed
route (20, 0), (120, 40), (220, 10), (320, 50) m and its constant current (0.03 m/s towards
90°), the straight case the same config with ``path.type: waypoints`` (built with
:func:`shipgym.scenarios.loader.scenario_from_dict`, not a catalogue entry).

Plant settings (the ``setting`` column; every row carries one):

* ``literal`` — the catalogue plant (the ``literal`` variant, rudder servo 0.1 s and rate
  limit 23.3 °/s at model scale, Froude-scaled from 2.33 °/s);
* ``literal_no_rate_limit`` — the same with the rudder rate limit lifted (``rudder_rate``
  = 100 rad/s full scale; the servo lag stays).  The paper's equations (8)–(16) have no
  steering gear: δ is the input.  This is our reading of the paper's plant;
* ``intended_fix`` — the corrected equations (data file §1.7), catalogue steering.

The identification runs on each setting's own model (the steering gear changes the
zig-zag, hence the fit and the gains): the controllers design on what they identify.

Statistics (Tables 2–3 print "mean value and standard deviation" of "cross-track errors",
"heading errors" and "rudder", without saying signed or absolute): both readings are
reported.  Signed: e [m], ψd − ψ [deg] (the autopilot's heading error: Figures 9–13 plot ψ
against ψd), δ [deg]; absolute: |e|, |ψd − ψ|, |δ| — |e| and |δ| as the leaderboard's
``mean_abs_cross_track`` etc. (:func:`shipgym.metrics.compute_metrics`, converted to
degrees).  The paper's numbers are attached to both readings.  ``mean_abs_path_heading_
error_deg`` is the leaderboard's |ψ − χf| (heading against the path tangent: it includes
the intercept angle of the guidance law), no published counterpart.  Samples: the
``n`` end-of-step samples of the metrics for e and δ; the ``n`` samples at which the
autopilot acted for ψd − ψ.  The scenario is deterministic (constant current, no noise):
extra seeds repeat the same episode.

Writes ``xu2020.md`` / ``.json`` and, per case, ``xu2020_{case}.png`` (track, ψ and ψd,
e(t), δ(t) of both controllers for each setting, first gains design).

Parts (:mod:`shipgym_baselines.reproduce.protocol`): :mod:`.scenarios` (cases and plant settings),
:mod:`.published` (the paper's numbers), :mod:`.controllers` (the laws, logging ψd, and the
gain designs), :mod:`.identification` (§5), :mod:`.metrics` (one episode's figures),
:mod:`.experiment` (the runs and rows), :mod:`.claims` (VF against LOS as the tables
order them), :mod:`.tables` (the markdown), :mod:`.figures` (the plots).
"""

from shipgym_baselines.reproduce.protocol import Reproduction
from shipgym_baselines.reproduce.xu2020.experiment import run_experiment
from shipgym_baselines.reproduce.xu2020.figures import plots
from shipgym_baselines.reproduce.xu2020.tables import report

REPRODUCTION = Reproduction("xu2020", run_experiment, report, plots)
