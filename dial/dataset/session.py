"""One run into a dataset: ``dial.run(..., dataset=...)`` and ``dial run --dataset``."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from dial.dataset.plan import Request, expected_features
from dial.dataset.recorder import Recorder
from dial.dataset.writer import DatasetWriter
from dial.parser.script import Script
from dial.scene.of_script import script_world


@contextmanager
def recording(
    dataset: str | Path | DatasetWriter, request: Request, script: Script, perturb_mm: float
) -> Iterator[Recorder]:
    """Check the run's features against the dataset, yield the observer that records it,
    and write its episode once the run has returned (an interrupted run has none). A
    folder given by its path is opened and closed here; a writer stays open."""
    writer = (
        dataset if isinstance(dataset, DatasetWriter) else DatasetWriter(dataset, fps=request.fps)
    )
    try:
        writer.check(expected_features(script_world(script), request))
        recorder = Recorder(Path(script.path).name, writer.fps, request.cameras, perturb_mm)
        yield recorder
        if recorder.episode is not None:
            writer.add(recorder.episode)
    finally:
        if writer is not dataset:
            writer.close()
