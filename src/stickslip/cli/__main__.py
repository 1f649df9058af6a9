"""``python -m stickslip.cli``: the ``stickslip`` command."""

from stickslip.cli import main

if __name__ == "__main__":  # not on import (the API reference imports every module)
    raise SystemExit(main())
