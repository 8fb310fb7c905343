"""Where each move of a leg's plan comes from in its program, found once and extended as the program
grows at its end (an open job's lines): a feed override or an open job's new lines then plan the
rest again from a move without reading the program from its start each time."""

from __future__ import annotations

from array import array
from bisect import bisect_left
from dataclasses import replace

from ..config import MachineConfig
from ..planner.program import Item, LinearMove, Program, SetOutputs


class MoveItems:
    """The items of a program planned from stepper positions `start`: the index of each move's item
    (counted as the planner counts moves: moves too short for a step are not moves) and of each
    output setting. Valid for a program whose items begin with those read so far; another program
    is read again from its start."""

    def __init__(self, config: MachineConfig, start: tuple[int, ...]) -> None:
        self.config = config
        self.start = start
        self._reset()

    def _reset(self) -> None:
        self._current = self.start
        self._moves = array("i")  # item index of each move
        self._outputs = array("i")  # item index of each SetOutputs
        self._read = 0
        self._last: Item | None = None  # the last item read, to know the program again

    def _follow(self, program: Program, until: int | None = None, move: int | None = None) -> None:
        """Read `program`'s items up to item `until` (excluded) or until move `move` is found."""
        items = program.items
        if self._read > len(items) or (self._read and items[self._read - 1] is not self._last):
            self._reset()
        to_steps = self.config.to_steps
        while self._read < len(items) and (until is None or self._read < until):
            if move is not None and move < len(self._moves):
                return
            item = items[self._read]
            if isinstance(item, SetOutputs):
                self._outputs.append(self._read)
            elif isinstance(item, LinearMove):
                target = to_steps(item.target)
                if target != self._current:
                    self._moves.append(self._read)
                    self._current = target
            self._last = item
            self._read += 1

    def item_of(self, program: Program, move: int) -> int:
        """The index in program.items of move number `move`; len(items) when there is none."""
        self._follow(program, move=move)
        return self._moves[move] if move < len(self._moves) else len(program.items)

    def rest_of(self, program: Program, first: int) -> Program:
        """`program` from its item `first` on, the outputs as they were there (as
        remainder.rest_of)."""
        self._follow(program, until=first)
        before = bisect_left(self._outputs, first)
        outputs = [program.items[self._outputs[before - 1]]] if before else []
        return replace(program, items=outputs + program.items[first:])
