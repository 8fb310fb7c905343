"""A GRBL 1.1 front door: G-code senders (UGS, CNCjs, bCNC, Candle, LightBurn) drive a quadstep
machine over a pseudo-terminal or TCP as they would drive a GRBL board (docs/SENDERS.md).

`protocol` splits the byte stream into lines and realtime commands and formats GRBL's answers,
`errors` maps quadstep's errors to GRBL's numbers and `alarms` its alarms, `settings` shows the
configuration as `$$` and `settings_write` writes `$N=value` into the file, `reader` checks each
line with the modal state of the lines before it, `executor` plans and runs what was read, `probe`
runs G38.x, `overrides` the override and coolant bytes, `status` answers `?`, `session` is one
client's conversation and `server` serves it.
"""
