"""The models of ``tailbeam learn``: scikit-learn pipelines, and what each one reads.

- ``forest``: the feature table's ``<sensor>.<feature>`` columns (tailbeam.study.features)
  through a median imputer (for features undefined on a window, e.g. the decay rate of a
  window whose loudest frame is its last), a standard scaler and a random forest of
  ``TREES`` trees unless told otherwise (classifier for ``label``, regressor for
  ``gangue_fraction``).
- ``minirocket``: the raw windows the features are computed of, one channel per sensor,
  through sktime's ``MiniRocketMultivariate`` (about 10,000 convolution features: the
  proportion of positive values of random dilated kernels), a standard scaler and a ridge
  model whose regularisation is chosen by leave-one-out among 10 values from 1e-3 to 1e3
  (``RidgeClassifierCV`` / ``RidgeCV``), the classifier of MiniRocket's authors (Dempster,
  Schmidt and Webb, KDD 2021).

``normalise`` makes either input blind to a sensor's gain: the forest keeps only the
scale-free features (every feature but the amplitudes ``SCALE_FEATURES``), MiniRocket gets
each window divided by its own RMS.
"""

import functools

import numpy as np

from tailbeam.study.features import SCALE_FEATURES, is_feature_name

MODELS = ("forest", "minirocket")
TREES = 200  # the forest's trees by default
RIDGE_ALPHAS = np.logspace(-3, 3, 10)


def feature_columns(table, sensors=None, *, scale_free=False) -> list:
    """Signal-feature columns (``<sensor>.<feature>``), optionally of some sensors only, and
    only the scale-free ones (``scale_free``)."""
    cols = []
    for c in table.columns:
        sensor, _, name = c.partition(".")
        if not is_feature_name(name) or (sensors is not None and sensor not in sensors):
            continue
        if not (scale_free and name in SCALE_FEATURES):
            cols.append(c)
    return cols


def normalised(windows) -> np.ndarray:
    """``windows`` (..., samples) each divided by its own RMS (a silent window stays 0)."""
    w = np.asarray(windows, dtype=float)
    level = np.sqrt(np.mean(np.square(w), axis=-1, keepdims=True))
    return np.divide(w, level, out=np.zeros_like(w), where=level > 0)


def forest(classify: bool, seed: int, trees: int = TREES):
    """Imputer, scaler and random forest of ``trees`` trees."""
    from sklearn.ensemble import RandomForestClassifier, RandomForestRegressor
    from sklearn.impute import SimpleImputer
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    model = RandomForestClassifier if classify else RandomForestRegressor
    return make_pipeline(
        SimpleImputer(strategy="median"),
        StandardScaler(),
        model(n_estimators=trees, random_state=seed, n_jobs=1),
    )


def minirocket(classify: bool, seed: int):
    """MiniRocket features, scaler and ridge (classifier or regressor) on windows
    (rows, sensor, samples)."""
    from sklearn.linear_model import RidgeClassifierCV, RidgeCV
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    ridge = RidgeClassifierCV if classify else RidgeCV
    return make_pipeline(
        _rocket_step()(random_state=seed), StandardScaler(), ridge(alphas=RIDGE_ALPHAS)
    )


@functools.cache
def _rocket_step():
    """A scikit-learn transformer holding sktime's MiniRocketMultivariate: a pipeline step of
    scikit-learn's own kind (sktime's fit resets attributes a scikit-learn pipeline sets on its
    steps), numpy in (rows, channels, samples), numpy out (rows, ~10,000)."""
    from sklearn.base import BaseEstimator, TransformerMixin

    class MiniRocketFeatures(TransformerMixin, BaseEstimator):
        def __init__(self, random_state=0):
            self.random_state = random_state

        def fit(self, x, y=None):
            from sktime.transformations.panel.rocket import MiniRocketMultivariate

            rocket = MiniRocketMultivariate(random_state=self.random_state, n_jobs=1)
            self.rocket_ = rocket.fit(np.asarray(x, dtype=float))
            return self

        def transform(self, x):
            return np.asarray(self.rocket_.transform(np.asarray(x, dtype=float)), dtype=float)

    return MiniRocketFeatures


def make(kind: str, classify: bool, seed: int, trees: int = TREES):
    """The pipeline of model ``kind`` (one of MODELS); ``trees``: the forest's."""
    if kind == "forest":
        return forest(classify, seed, trees)
    return minirocket(classify, seed)


def dummy(classify: bool):
    """The floor: the majority class or the mean of the training rows."""
    from sklearn.dummy import DummyClassifier, DummyRegressor

    return DummyClassifier(strategy="most_frequent") if classify else DummyRegressor()
