"""The command line: argparse with one-line errors (:mod:`.parser`), each command's
arguments (:mod:`.arguments`, the checks' in :mod:`.checks`), its words (:mod:`.text`),
progress bars (:mod:`.progress`), the commands (:mod:`.commands`: parse, call
:mod:`rigidfold.pipeline`, print) and the process entry (:mod:`.launch`). The top layer:
nothing imports it."""
