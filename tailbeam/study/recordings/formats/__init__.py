"""The recording file formats: one reader per format, each giving a ``Recording``.

- ``recording``: what a reader gives: channel names, sample rate and units as the file says
  them, and the samples block by block;
- ``wav``, ``csvfile``, ``uff``, ``tdms``, ``matfile``, ``hdf5``: one reader per format, with
  ``arrays`` (the rule that turns the variables of a MAT or HDF5 file into channels);
- ``readers``: which reader opens which file extension (``open_recording``).
"""
