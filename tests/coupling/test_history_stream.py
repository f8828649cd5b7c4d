"""history.csv written in pieces while the run goes on (coupling.app.history_stream): a
table's pieces are the whole table's bytes, a run's pieces and its rest are the history.csv
one process writes after the run, and where the pieces cannot stand for the run's result
(another resolution, records that changed, a writer that refused a piece) the table is
written whole."""

from __future__ import annotations

import numpy as np
import pytest

from coupling.app import arrow_text, history_stream
from coupling.app.output import csv_rows, history_codes, thin_history, write_csv, write_csv_pieces
from coupling.core.master import CoSimulation
from coupling.core.scene import builtin_scene


def table(n: int, seed: int = 3) -> tuple[dict, dict]:
    """Columns of every kind write_csv meets in a history: floats of every formatting class
    (arrow_text's probe values), NaN, -0.0, a constant column, integers, a coded column."""
    rng = np.random.default_rng(seed)
    probe = arrow_text.probe_values()
    floats = np.resize(np.concatenate([probe, [np.nan, -0.0, 0.0]]), n)
    columns = {"time": np.linspace(0.0, 1e-3, n), "x": rng.permutation(floats), "y": rng.standard_normal(n) * 1e-6,
               "flat": np.full(n, 0.25), "count": np.arange(n) - 7, "regime_0": rng.integers(0, 3, n)}
    return columns, {"regime_0": ("free", "slip", "stick")}


@pytest.mark.parametrize("cuts", [(1,), (17, 18, 600), (2000, 2001), (5, 3000, 5999)])
def test_a_table_in_pieces_is_the_whole_tables_bytes(tmp_path, cuts):
    """Pieces of one row, of a few rows (csv_rows' Python route) and of thousands (Arrow's),
    against write_csv of the whole table."""
    columns, codes = table(6000)
    write_csv(tmp_path / "whole.csv", columns, codes)
    bounds = (0, *cuts, 6000)
    parts = [{k: v[a:b] for k, v in columns.items()} for a, b in zip(bounds[:-2], bounds[1:-1])]
    rest = {k: v[bounds[-2]:] for k, v in columns.items()}
    write_csv_pieces(tmp_path / "pieces.csv", rest, codes, [csv_rows(p, codes) for p in parts])
    assert (tmp_path / "pieces.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


class Writer:
    """A table writer's send_piece, keeping each piece's text as the helper does."""

    def __init__(self, refuse_after: int | None = None):
        self.pieces: dict[int, list[bytes]] = {}
        self.refuse_after = refuse_after

    def send_piece(self, stream, columns, codes):
        held = self.pieces.setdefault(stream, [])
        if self.refuse_after is not None and len(held) >= self.refuse_after:
            return False
        held.append(csv_rows(columns, codes))
        return True


def relay(t_end: float = 0.002):
    return builtin_scene("relay_force").set("solver.t_end", t_end)


def streamed_run(scene, writer, monkeypatch, rows: int = 100):
    """A coupled run of ``scene`` watched by a HistoryStream sending pieces of ``rows``
    records to ``writer``; (stream, the run's result)."""
    monkeypatch.setattr(history_stream, "PIECE_ROWS", rows)
    stream = history_stream.HistoryStream(writer, scene)
    result = CoSimulation(scene, watch=stream).run()
    return stream, result


def whole_and_streamed(tmp_path, stream, writer, result) -> tuple[bytes, bytes | None]:
    m = result.mechanics
    interval = result.scene.output.history_interval(float(m.t[-1] - m.t[0]))
    kept = thin_history(m, interval)
    write_csv(tmp_path / "whole.csv", m.select(kept).history_columns, history_codes())
    rest = stream.finish(m, kept, interval)
    if rest is None:
        return (tmp_path / "whole.csv").read_bytes(), None
    assert len(writer.pieces[stream.stream]) == len(stream.pieces)
    write_csv_pieces(tmp_path / "pieces.csv", m.select(rest).history_columns, history_codes(),
                     writer.pieces[stream.stream])
    return (tmp_path / "whole.csv").read_bytes(), (tmp_path / "pieces.csv").read_bytes()


def test_a_runs_pieces_and_its_rest_are_the_history_written_after_the_run(tmp_path, monkeypatch):
    """The relay's make (impacts, stick and slip, the events' thinning): pieces made while
    it runs, the rest after, the bytes of the table written whole."""
    writer = Writer()
    stream, result = streamed_run(relay(), writer, monkeypatch)
    assert len(stream.pieces) >= 3  # (the run made pieces, not one table at the end)
    assert result.mechanics.thinning is None
    whole, pieces = whole_and_streamed(tmp_path, stream, writer, result)
    assert pieces == whole


def test_a_second_run_starts_the_stream_again(tmp_path, monkeypatch):
    """A run again (as with refined modes) gets a new table: its pieces, not the first run's."""
    writer = Writer()
    stream, first = streamed_run(relay(0.001), writer, monkeypatch)
    old = stream.stream
    second = CoSimulation(relay(0.0015), watch=stream).run()
    assert stream.stream != old and stream.pieces
    assert stream.finish(first.mechanics, thin_history(first.mechanics, stream.interval), stream.interval) is None
    whole, pieces = whole_and_streamed(tmp_path, stream, writer, second)
    assert pieces == whole


def test_pieces_that_cannot_stand_for_the_result_are_dropped(monkeypatch):
    """Another resolution (a run that stopped early), a record that is not what a piece was
    made of, an event that would credit a piece's rows otherwise: finish says None, and the
    table is written whole."""
    writer = Writer()
    stream, result = streamed_run(relay(), writer, monkeypatch)
    m = result.mechanics
    kept = thin_history(m, stream.interval)
    assert stream.finish(m, kept, stream.interval) is not None
    assert stream.finish(m, thin_history(m, 2 * stream.interval), 2 * stream.interval) is None
    k = stream.pieces[1][0][3]
    states = m.states.copy()
    states[k, 0] = np.nextafter(states[k, 0], np.inf)
    changed = type(m)(**{**{f: getattr(m, f) for f in ("model", "t", "aux", "peak_force", "regimes", "events",
                                                       "stats", "projection_energy", "extra_states")},
                         "states": states})
    assert stream.finish(changed, kept, stream.interval) is None
    seated = [*m.events, {"kind": "armature_seat", "time": float(m.t[1]), "energy": 1e-9}]
    credited = type(m)(**{**{f: getattr(m, f) for f in ("model", "t", "states", "aux", "peak_force", "regimes",
                                                        "stats", "projection_energy", "extra_states")},
                          "events": seated})
    assert stream.finish(credited, kept, stream.interval) is None
    assert stream.finish(m, kept[1:], stream.interval) is None  # (a table that lacks a piece's record)


def test_a_writer_that_refuses_a_piece_stops_the_stream(monkeypatch):
    writer = Writer(refuse_after=1)
    stream, result = streamed_run(relay(), writer, monkeypatch)
    assert not stream.sending and len(stream.pieces) == 1
    m = result.mechanics
    kept = thin_history(m, stream.interval)
    rest = stream.finish(m, kept, stream.interval)
    # the one piece it took still stands; the rest is everything after it
    assert rest is not None and rest[0] >= stream.decided and len(rest) + len(stream.pieces[0][0]) == len(kept)


def test_a_long_history_sends_pieces_up_to_its_cap_and_the_rest_at_the_end(tmp_path, monkeypatch):
    """What the helper holds is bounded (STREAM_ROWS_MAX rows): past it, the run's later rows
    go in the last piece, and the table is still the whole table's bytes."""
    monkeypatch.setattr(history_stream, "STREAM_ROWS_MAX", 1000)
    writer = Writer()
    stream, result = streamed_run(relay(), writer, monkeypatch)
    assert not stream.sending and 2 <= len(stream.pieces) and stream.rows <= 1000
    whole, pieces = whole_and_streamed(tmp_path, stream, writer, result)
    assert pieces == whole


def test_a_watcher_that_fails_never_stops_the_run(monkeypatch):
    class Broken(Writer):
        def send_piece(self, *args):
            raise RuntimeError("no")

    stream, result = streamed_run(relay(), Broken(), monkeypatch)
    assert result.mechanics.t[-1] == result.scene.t_end  # (the run went on to its end)
    assert not stream.sending and not stream.pieces
