"""Benchmarks: each module's ``run()`` returns figures measured against the issues' targets."""
