"""Parts of the adaptive backstepping heading controllers of Xu, Oliveira & Guedes Soares
(2021), one module per idea, for :mod:`shipgym_baselines.classical.l1_backstepping`.

* :mod:`.design_model` — the design model T·ṙ + H(r)·r = K·δ + b, eq. (15), and its nominal
  values for a ship;
* :mod:`.projection` — the smooth projection operator of the adaptation laws, eqs. (24)–(25);
* :mod:`.predictor` — the state predictor, eq. (20), with its projection adaptation;
* :mod:`.lowpass` — the low-pass filter C(s), eq. (39), discretised exactly (ZOH);
* :mod:`.backstepping` — the backstepping law, eqs. (27)–(35);
* :mod:`.settings` — the §5.2 gains and their transfer to another ship;
* :mod:`.loop_analysis` — the law linearised on its design model: closed-loop poles.
"""
