"""history.csv's rows sent to the table writer while the run goes on.

``switchsim run`` hands its large tables to a helper process (coupling/app/table_writer.py).
history.csv was the longest of them: the default relay's ~5 700 rows x 75 columns took the
helper ~75 ms of text after the run, the last thing the command waited for. Most of its rows
are known long before the run ends: a macro step never returns to a time before its own
start, so after each one every record the mechanics holds is final, and history.csv's
thinning (``output.thin_history``) decides a record from its neighbours and the events near
it. ``HistoryStream`` watches the run (``CoSimulation``'s ``watch``) and, every ``PIECE_ROWS``
records decided, sends those records' rows to the helper, which turns them into text on the
other CPU while the run goes on. ``write_files`` then sends the rest, and the helper writes
the header, the pieces and the rest.

The same bytes as the table written whole: each row depends on its own record, the run's
first record (the energy audit's origin, ``mech.ImpactSolver.records``) and the events before
it, and a piece's text is the whole table's text of its rows (``output.csv_rows``). At the
end ``finish`` checks what that needs rather than assuming it: the whole table's thinning
keeps the pieces' records and no other before the last of them; those records (times,
states, contact values, regimes) are the ones the pieces were made of; the events credit
their rows as they did then; the history's resolution is the one the pieces used. Where any
of that fails (a run again with refined modes, the solver's own thinning of a long history,
an interrupted or failed run, whose span sets another resolution) the pieces are dropped and
the table is written whole, as without the stream. A watcher that fails stops sending; it
never stops the run.
"""

from __future__ import annotations

import numpy as np

from mech.results import seat_credit

from coupling.app.output import history_codes, kept_records

# records a piece: ~500 rows of a relay's 75 columns (37 500 cells, Arrow's route in the
# helper); the last piece, sent after the run, is at most about this long
PIECE_ROWS = 512
# records sent in pieces at most: the helper holds their text until the end (~1.1 kB a row of
# the default relay's 75 columns: ~18 MB) and this process a copy of their records to check
# them against the result (~0.6 kB a row); a longer history's later rows go in the last
# piece, as the whole table did (history.csv keeps at most [output] history_max_rows, 50 000)
STREAM_ROWS_MAX = 16_384


class HistoryStream:
    """Sends history.csv's decided rows to ``writer`` (a TableWriter) as the run of ``scene``
    goes on: call it with the mechanics solver after every macro step (``CoSimulation``'s
    ``watch``); ``finish`` says which records are left for the last piece."""

    def __init__(self, writer, scene):
        self.writer = writer
        self.codes = history_codes()  # the regime columns' names, as write_files writes them
        # s: the resolution of a run that reaches its end (a shorter one's is checked again)
        self.interval = scene.output.history_interval(scene.t_end)
        self.stream = 0
        self.solver = None
        self._start(None)

    def _start(self, solver) -> None:
        self.stream += 1  # (a new run's pieces go to a new table; the old ones are never asked for)
        self.solver = solver
        self.sending = solver is not None
        self.decided = 0  # records [0, decided) are decided: kept and sent, or left out
        self.pieces: list[tuple] = []  # each piece's (kept indices, t, states, aux, regimes, events)

    @property
    def rows(self) -> int:
        """Rows sent in pieces."""
        return sum(len(piece[0]) for piece in self.pieces)

    def __call__(self, solver) -> None:
        try:
            self._watch(solver)
        except Exception:  # noqa: BLE001 - the table is then written whole; the run goes on
            self.sending = False

    def _watch(self, solver) -> None:
        if solver is not self.solver:  # the first macro step, or a run again (refined modes)
            self._start(solver)
        if not self.sending:
            return
        if solver.thinning["rows_dropped"]:  # the solver thinned its history: indices moved
            self.sending = False
            return
        rec = solver.recorder
        stop = rec.n - 1  # the last record's row depends on what comes after it
        if stop - self.decided < PIECE_ROWS:
            return
        kept = kept_records(rec.t[:rec.n], rec.regime[:rec.n], np.array([e["time"] for e in solver.events], float),
                            self.interval, self.decided, stop)
        if self.rows + len(kept) > STREAM_ROWS_MAX:  # (the rest goes in the last piece)
            self.sending = False
            return
        piece = solver.records(kept)
        if not self.writer.send_piece(self.stream, piece.history_columns, self.codes):
            self.sending = False
            return
        self.pieces.append((kept, piece.t, piece.states, piece.aux, piece.regimes, piece.events))
        self.decided = stop

    def finish(self, mres, kept: np.ndarray, interval: float) -> np.ndarray | None:
        """The records of ``kept`` (the whole table's, ``output.thin_history`` of the run's
        result ``mres`` at ``interval``) the pieces do not hold, or None if the pieces cannot
        stand for the rest (module docstring): then the table is written whole."""
        if not self.pieces or interval != self.interval or mres.thinning is not None:
            return None
        sent = np.concatenate([p[0] for p in self.pieces])
        n = len(sent)
        if len(kept) <= n or not np.array_equal(kept[:n], sent) or kept[n] < self.decided:
            return None
        for idx, t, states, aux, regimes, events in self.pieces:
            if not (np.array_equal(mres.t[idx], t) and np.array_equal(mres.states[idx], states)
                    and np.array_equal(mres.aux[idx], aux) and np.array_equal(mres.regimes[idx], regimes)
                    and np.array_equal(seat_credit(t, mres.events), seat_credit(t, events))):
                return None
        return kept[n:]
