"""Progress of a scan: a tqdm bar (the ``progress`` extra), a callback, or nothing."""

from __future__ import annotations

__all__ = ["progress_reporter"]


class _Callback:
    def __init__(self, callback, total: int):
        self.callback = callback
        self.total = total

    def update(self, done: int) -> None:
        self.callback(done, self.total)

    def close(self) -> None:
        pass


class _Bar:
    def __init__(self, tqdm, total: int):
        # disable=None: quiet when stderr is not a terminal.
        self.bar = tqdm(total=total, unit="pt", unit_scale=True, disable=None, smoothing=0.1)
        self.done = 0

    def update(self, done: int) -> None:
        self.bar.update(done - self.done)
        self.done = done

    def close(self) -> None:
        self.bar.close()


def progress_reporter(progress, total: int):
    """An object with ``update(points_done)`` and ``close()``.

    Parameters
    ----------
    progress : None, bool or callable
        None: a tqdm bar if tqdm is installed; True: a tqdm bar (tqdm required); either is
        quiet when stderr is not a terminal. False: nothing. A callable is called as
        ``progress(points_done, points_total)`` after each chunk; a KeyboardInterrupt it
        raises stops the scan like Ctrl-C.
    total : points, the scan's size.
    """
    if callable(progress):
        return _Callback(progress, total)
    if progress is False:
        return _Callback(lambda done, total: None, total)
    try:
        from tqdm import tqdm
    except ImportError:
        if progress is None:
            return _Callback(lambda done, total: None, total)
        raise ImportError("a progress bar needs tqdm: pip install 'epc-fast[progress]'") from None
    return _Bar(tqdm, total)
