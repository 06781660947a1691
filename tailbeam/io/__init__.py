"""Input and output: scene files (reading, writing back), result files (CSV, NPZ) and the
output folder with its manifest.
"""
