"""The studies: measures, referees and the reproductions that the report and the tests share.

- measures and referees: ``metrics`` (ΔE statistics, ColorChecker truth), ``stats`` (chi-square),
  ``chi2_cases`` (every sampler's chi-square case), ``oracles`` (mpmath);
- Wang et al.: ``phong``, ``phong_table1``, ``phong_figures``;
- Herbert et al.: ``env_accuracy``, ``shrm_fullres``, ``spectral_env``;
- Ferwerda: ``impastor``, ``impastor_lighting``, ``impastor_hybrid``, ``impastor_commands``;
- across the papers: ``crosscheck`` (Mitsuba 3), ``sweep`` (user-defined sweeps).
"""
