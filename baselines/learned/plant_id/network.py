"""The estimator φ: an MLP from a window to each slot's mean and variance.

φ(window) = (μ, ln σ²) per slot (:data:`~.labels.SLOTS`), trained by the Gaussian negative
log-likelihood ½[(y − μ)²/σ² + ln σ²] over the slots the ship has (Nix & Weigend 1994; the
predicted variance is the uncertainty the controller reads).  Inputs are standardised by
the training data's mean and standard deviation, kept with the weights.  Torch runs on one
thread (:func:`one_thread`): on two cores more threads are slower.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np

#: hidden layers of φ
HIDDEN = (256, 256)
#: the file of the weights and the standardisation; its description beside it
WEIGHTS_FILE = "estimator.pt"
META_FILE = "meta.json"
#: ln σ² is kept in [LOG_VAR_MIN, LOG_VAR_MAX] (a variance of e^-12 … e^4 slot units²)
LOG_VAR_MIN, LOG_VAR_MAX = -12.0, 4.0


def one_thread() -> Any:
    """torch, set to one thread (a :class:`~shipgym_baselines.extras.MissingExtra` naming
    the ``rl`` extra when torch is not installed)."""
    from shipgym_baselines.extras import require

    require("torch", "rl", "nmpc_learned_id")
    import torch

    torch.set_num_threads(1)
    return torch


def build(inputs: int, outputs: int, seed: int) -> Any:
    """φ with ``inputs`` features and 2·``outputs`` outputs (μ, ln σ²), seeded."""
    torch = one_thread()
    torch.manual_seed(seed)
    layers: list[Any] = []
    width = inputs
    for hidden in HIDDEN:
        layers += [torch.nn.Linear(width, hidden), torch.nn.Tanh()]
        width = hidden
    layers.append(torch.nn.Linear(width, 2 * outputs))
    return torch.nn.Sequential(*layers)


def nll(output: Any, target: Any, mask: Any) -> Any:
    """The masked Gaussian NLL per sample, averaged (module doc)."""
    torch = one_thread()
    mean, log_var = output.chunk(2, dim=-1)
    log_var = torch.clamp(log_var, LOG_VAR_MIN, LOG_VAR_MAX)
    terms = 0.5 * ((target - mean) ** 2 * torch.exp(-log_var) + log_var)
    return (terms * mask).sum() / mask.sum().clamp(min=1.0)


class Estimator:
    """φ with its input standardisation: :meth:`predict` gives (μ, σ²) per slot."""

    def __init__(self, net: Any, mean: np.ndarray, std: np.ndarray, meta: dict) -> None:
        self.net, self.mean, self.std, self.meta = net, mean, std, meta
        self.net.eval()

    def predict(self, inputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(μ, σ²) of (…, n_in) windows, each (…, n_slots)."""
        torch = one_thread()
        x = (np.asarray(inputs, dtype=np.float32) - self.mean) / self.std
        with torch.no_grad():
            out = self.net(torch.from_numpy(x.astype(np.float32))).numpy()
        mean, log_var = np.split(out, 2, axis=-1)
        return mean.astype(float), np.exp(np.clip(log_var, LOG_VAR_MIN, LOG_VAR_MAX))

    def save(self, folder: Path) -> None:
        """The weights and standardisation (``estimator.pt``) and ``meta.json``, each
        written whole through no link (:mod:`shipgym_baselines.records.outfiles`; a run
        folder's manifest lists them)."""
        from shipgym_baselines.records.outfiles import make_dir, write_bytes, write_text

        torch = one_thread()
        if not folder.is_dir():
            folder.parent.mkdir(parents=True, exist_ok=True)
            make_dir(folder)
        weights = io.BytesIO()
        torch.save(
            {
                "state_dict": self.net.state_dict(),
                "mean": torch.from_numpy(self.mean),
                "std": torch.from_numpy(self.std),
            },
            weights,
        )
        write_bytes(folder / WEIGHTS_FILE, weights.getvalue())
        write_text(folder / META_FILE, json.dumps(self.meta, indent=1) + "\n")

    @classmethod
    def load(cls, folder: Path) -> Estimator:
        """The estimator saved in ``folder`` (weights only: no pickled code is loaded)."""
        torch = one_thread()
        meta = json.loads((folder / META_FILE).read_text())
        data = torch.load(folder / WEIGHTS_FILE, map_location="cpu", weights_only=True)
        net = build(meta["inputs"], meta["outputs"], 0)
        net.load_state_dict(data["state_dict"])
        return cls(net, data["mean"].numpy(), data["std"].numpy(), meta)
