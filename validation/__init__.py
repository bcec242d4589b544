"""specref validation: metrics, oracles, report, charts and the command line."""
