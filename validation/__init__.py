"""specref's validation: the studies, the report and the ``specref`` command line.

- :mod:`validation.studies` — measures, mpmath oracles, chi-square cases and the reproductions of
  each paper's tables and figures;
- :mod:`validation.report` — ``specref report`` (its sections in ``validation.report.sections``) and
  the equation index;
- :mod:`validation.cli` — the ``specref`` command, one module per subcommand (dispatch only);
- :mod:`validation.precompute` — scripts that write the precomputed data files.

Nothing imports ``validation``.
"""
