"""What the machine layer refuses, with a message that says why and what to change."""


class MachineError(Exception):
    """The machine cannot do what was asked: its firmware disagrees with the configuration, it is
    busy with another program, or it is not at rest."""
