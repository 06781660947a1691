"""Figures of a learn result (tailbeam.study.learn): confusion matrix and importances, PNG."""

import numpy as np


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def confusion_title(scores: dict) -> str:
    """The confusion figure's title: the model's accuracy beside the majority class's."""
    floor = scores["dummy"]["accuracy"]
    return (
        f"{scores.get('model', 'forest')}: accuracy {scores['accuracy']:.1%} "
        f"(majority class {floor:.1%}), F1 {scores['f1_macro']:.2f}\n"
        f"({scores['n_rows']} windows, {scores['n_cases']} cases, grouped {scores['folds']}-fold)"
    )


def confusion_figure(scores: dict, path, title: str = ""):
    """Confusion matrix (counts and row fractions) of a classification result, as a PNG; the
    title gives the accuracy beside the majority-class baseline's."""
    plt = _pyplot()
    cm = np.asarray(scores["confusion"], dtype=float)
    frac = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
    fig, ax = plt.subplots(figsize=(4.6, 3.9), constrained_layout=True)
    ax.imshow(frac, cmap="Blues", vmin=0, vmax=1)
    for i in range(cm.shape[0]):
        for j in range(cm.shape[1]):
            colour = "white" if frac[i, j] > 0.6 else "black"
            ax.text(j, i, f"{cm[i, j]:.0f}\n{frac[i, j]:.0%}", ha="center", va="center",
                    color=colour)  # fmt: skip
    ticks = range(len(scores["classes"]))
    ax.set_xticks(ticks, scores["classes"])
    ax.set_yticks(ticks, scores["classes"])
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    ax.set_title(title or confusion_title(scores), fontsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def importance_figure(scores: dict, path, top: int = 15):
    """Bar chart of the ``top`` largest feature importances (of all of them), as a PNG."""
    plt = _pyplot()
    every = list(scores["importances"].items())
    items = every[:top][::-1]
    fig, ax = plt.subplots(figsize=(5.5, 0.25 * len(items) + 1.2), constrained_layout=True)
    ax.barh([k for k, _ in items], [v for _, v in items], color="tab:blue")
    ax.set_xlabel("importance (mean impurity decrease; all features sum to 1)")
    ax.set_title(
        f"random forest, target {scores['target']}: the top {len(items)} of {len(every)} "
        "features\n(band_, wp_: energy fractions)",
        fontsize=9,
    )
    ax.tick_params(axis="y", labelsize=8)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
