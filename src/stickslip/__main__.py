"""``python -m stickslip``: the ``stickslip`` command (the command line's entry point, like
:mod:`stickslip.cli.__main__`)."""

from stickslip.cli import main

if __name__ == "__main__":  # not on import (the API reference imports every module)
    raise SystemExit(main())
