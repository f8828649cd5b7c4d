"""Data files shipped with switchsim: tribometer_illustrative.csv (ILLUSTRATIVE, NOT MEASURED; see docs/tribology.md)."""
