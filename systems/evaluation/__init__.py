"""Scores: errors against optical references (`attitude evaluate`), peers on simulated
motion (`compare`), Rizun's experiments (`table1`) and throughput (`bench`)."""
