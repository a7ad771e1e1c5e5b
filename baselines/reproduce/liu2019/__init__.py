"""Liu et al. (2019) §4: Cases 1–3 with NMPC, NMPC + weighted LS-SVM, NMPC + λ-LS-SVM.

For every case, controller and unit reading of the nomoto2 parameters (``si``, the
library's default, and ``rudder_degrees``, the agile reading that reaches the paper's
convergence times) this runs the catalogue scenario and reports our ACE and t_c beside the
published ones, writes ``liu2019.md`` / ``.json`` and, per case and reading, a
figure with the tracks, e(t), the identified parameters against the truth and λ_k.

Parts (:mod:`shipgym_baselines.reproduce.protocol`): :mod:`.experiment` (the runs and rows),
:mod:`.tables` (the markdown), :mod:`.figures` (the plots).
"""

from shipgym_baselines.reproduce.liu2019.experiment import run_experiment
from shipgym_baselines.reproduce.liu2019.figures import plots
from shipgym_baselines.reproduce.liu2019.tables import report
from shipgym_baselines.reproduce.protocol import Reproduction

REPRODUCTION = Reproduction("liu2019", run_experiment, report, plots)
