"""Analysis of logged scans: the canonical table, contact and windows, metrics,
comparison with real logs, identification, the rib detector and the claims.

Each rule (contact, scan window, contact loss, rib) is defined once, in
:mod:`vic_drake.analysis.contact` and :mod:`vic_drake.analysis.ribs`, and
used by every metric and claim.
"""
