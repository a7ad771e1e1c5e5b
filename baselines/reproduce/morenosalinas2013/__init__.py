"""Moreno-Salinas et al. (2013) §4: Blanke's model identified by LS-SVM from a 20/20 zig-zag.

The experiment, on the ``blanke`` plant (the naval vessel of Blanke & Christensen 1993; the
paper's scale ship and its coefficients are not available):

1. a 20/20 zig-zag for 90 s from straight running at 8 m/s, sampled at the paper's IMU rate
   (0.2 s), with the paper's one-sigma IMU figures as white Gaussian noise: velocity
   0.04 m/s on u and v, heading 0.05° (plotted only: the regression does not use ψ).  The
   paper gives no yaw-rate figure; ``yaw_rate_noise`` (default 0) adds one.  Noise comes
   from ``numpy.random.default_rng(seed)``, one realisation per seed;
2. :func:`shipgym.identification.blanke.fit_blanke` (§3, eq. (9)–(15)) on the measured
   u, v, r and the rudder angle;
3. the identified model replays the plant's rudder commands ("the same commanded input
   data", §4) from the same initial state: the training zig-zag (§4.1, fit), turning circles
   at −20° and +20° for 240 s (§4.2.1) and a 10/10 zig-zag for 90 s (§4.2.2);
4. the standard deviations of the errors identified − measured in surge, sway and yaw rate,
   as the paper reports them (`std_error_*`), and identified − noise-free plant
   (`std_error_*_vs_plant`, no published counterpart).

Two identifiers (the ``controller`` column): ``lssvm_blanke`` is the paper's procedure on the
raw samples; ``lssvm_blanke_lowpass`` first smooths u, v, r with a zero-phase 2nd-order
Butterworth low-pass at 0.5 Hz (our addition, not in the paper) to show how much of the
error is the errors-in-variables bias of white velocity noise in an Euler-differenced
regression.  Writes ``morenosalinas2013.md`` / ``.json``, the identified coefficients next to
the plant's (linearised) ones in ``morenosalinas2013_coefficients.json`` and a figure of the
time series (measured, plant, identified).

Parts (:mod:`shipgym_baselines.reproduce.protocol`): :mod:`.experiment` (the fits, replays and
rows), :mod:`.tables` (the markdown), :mod:`.figures` (the plots).
"""

from shipgym_baselines.reproduce.morenosalinas2013.experiment import run_experiment
from shipgym_baselines.reproduce.morenosalinas2013.figures import plots
from shipgym_baselines.reproduce.morenosalinas2013.tables import report
from shipgym_baselines.reproduce.protocol import Reproduction

REPRODUCTION = Reproduction("morenosalinas2013", run_experiment, report, plots)
