"""Measured accelerometer recordings into the dataset layout of a sweep (``tailbeam import``).

- ``formats``: one reader per file format, each giving a ``Recording`` (channel names, rate
  and units as the file says them, samples block by block), and which reader opens which
  file extension;
- ``units``: acceleration units and their factors to m/s^2;
- ``labels``: the labels file, one row per recording;
- ``resample``: block-wise rational resampling (scipy.signal.resample_poly);
- ``onsets``: impact onsets, an envelope over a robust noise floor, with a dead time;
- ``cut``: recordings into cases (one per file, fixed windows, or a window per onset);
- ``plan``: every check made before anything is written, and what was chosen;
- ``store``: the dataset written chunk by chunk (dataset.zarr, impacts.parquet, cases.csv);
- ``driver``: the plan run, file by file, block by block.
"""
