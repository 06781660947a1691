"""Labelled vibration datasets and how separable coal and gangue are (``tailbeam[study]``).

- ``sweep_file``: the sweep file (base scene, axes, repeats), with ``scene_keys`` (its dotted keys);
- ``design``: its expansion into cases, with ``labels`` (a case's coal / gangue labels);
- ``case``: one case, run on a Dask worker (labels, signals, impacts);
- ``sweep``: running the cases on Dask (local cluster or a scheduler), resumable;
- ``dataset``: the on-disk dataset (dataset.zarr, impacts.parquet, cases.csv);
- ``features``: signal features per window (pure numpy/scipy/PyWavelets functions);
- ``windows``: impact windows and fixed windows cut from the dataset, and the feature table;
- ``models``: the models of ``learn`` (random forest on features, MiniRocket on raw windows);
- ``learn``: their scores, cross-validated grouped by case and on another dataset, with
  ``learn_figures`` (confusion matrix, importances).

The optional dependencies (dask, xarray, zarr, pyarrow, scikit-learn, PyWavelets, sktime) are
imported inside the functions that need them, so ``import tailbeam`` stays light.
"""

STUDY_MODULES = ("dask.distributed", "xarray", "zarr", "pyarrow", "sklearn", "pywt", "pandas")


def require_study_dependencies() -> None:
    """Raise InputError naming the install command when an optional dependency is missing."""
    import importlib.util

    from tailbeam.errors import InputError

    missing = [m for m in STUDY_MODULES if importlib.util.find_spec(m.split(".")[0]) is None]
    if missing:
        raise InputError(
            "dependencies",
            f"{', '.join(missing)} not installed; they come with the study extra: "
            "pip install 'tailbeam[study]' from a package index, or from a checkout of "
            "tailbeam (the folder with pyproject.toml) pip install -e '.[study]'",
        )
