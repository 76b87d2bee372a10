"""Independent tasks in worker processes, where a task that fails or a worker that dies costs only that task.

concurrent.futures' process pool breaks as a whole when one worker dies, and cannot say which task killed it. Here the
main process hands each worker one task at a time over the worker's own pipes, so it always knows what a dead worker
was doing: that task is reported as failed, a new worker takes the dead one's place, and the other tasks go on. No
lock is shared between workers (a worker killed while holding one would stall the others). Workers ignore Ctrl-C
(the main process stops them) and leave when the main process is gone.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections import deque
from multiprocessing.connection import wait
from typing import Any, Callable, Iterator, Sequence

_POLL = 1.0  # seconds a worker waits for a task before checking that the main process is still there


class TaskFailed:
    """What a failed task gives instead of its result: the error's one-line message."""

    def __init__(self, message: str):
        self.message = message

    def __repr__(self) -> str:
        return f"TaskFailed({self.message!r})"


def run(fn: Callable[[Any], Any], tasks: Sequence, workers: int) -> Iterator[tuple[int, Any]]:
    """Yield (index, fn(tasks[index]) or TaskFailed) as the tasks finish, in `workers` spawned processes. Closing the
    iterator early (an exception in the caller, Ctrl-C) stops the workers."""
    with Pool(fn, min(workers, len(tasks))) as pool:
        yield from pool.run(tasks)


class Pool:
    """`workers` spawned processes running `fn`, kept from one batch of tasks to the next (a tuning study's trials pay
    for starting them once); `close` (or leaving a `with` block) stops them."""

    def __init__(self, fn: Callable[[Any], Any], workers: int):
        self.ctx, self.fn = multiprocessing.get_context("spawn"), fn
        self.workers = [_Worker(self.ctx, fn) for _ in range(workers)]

    def run(self, tasks: Sequence) -> Iterator[tuple[int, Any]]:
        """Yield (index, fn(tasks[index]) or TaskFailed) as the tasks finish. Closing the iterator early stops the
        workers: the pool is then spent."""
        pool, todo, finished = self.workers, deque(range(len(tasks))), False
        try:
            while todo or any(w.task is not None for w in pool):
                for k, w in enumerate(pool):
                    if w.task is None and todo:
                        if not w.process.is_alive():  # died while idle: replace it before giving it a task
                            pool[k] = w = _Worker(self.ctx, self.fn)
                        w.give(todo.popleft(), tasks)
                busy = {w.results: w for w in pool if w.task is not None}
                for conn in wait(list(busy)):
                    w = busy[conn]
                    try:
                        index, value = conn.recv()
                    except (EOFError, OSError):  # the pipe closed: the worker died inside its task
                        w.process.join(timeout=5)
                        index, value = w.task, TaskFailed(f"worker process died (exit code {w.process.exitcode})")
                        w.stop(wait=False)
                        pool[pool.index(w)] = _Worker(self.ctx, self.fn)
                    w.task = None
                    yield index, value
            finished = True
        finally:
            if not finished:
                self.close(wait=False)

    def close(self, wait: bool = True) -> None:
        """Stop the workers: let idle ones leave (`wait`), else terminate them."""
        for w in self.workers:
            w.stop(wait=wait)
        self.workers = []

    def __enter__(self) -> "Pool":
        return self

    def __exit__(self, *exc) -> None:
        self.close(wait=exc[0] is None)


class _Worker:
    """One worker process, its task and result pipes, and the index of the task it holds (None when idle)."""

    def __init__(self, ctx, fn):
        theirs, self.tasks = ctx.Pipe(duplex=False)
        self.results, mine = ctx.Pipe(duplex=False)
        self.process = ctx.Process(target=_serve, args=(fn, theirs, mine, os.getpid()), daemon=True)
        self.process.start()
        theirs.close()  # the worker's ends: closed here, so its death reads as the end of its result pipe
        mine.close()
        self.task: int | None = None

    def give(self, index: int, tasks: Sequence):
        self.task = index
        self.tasks.send((index, tasks[index]))

    def stop(self, wait: bool):
        """End the process: let it leave its loop when it is idle (`wait`), else terminate it."""
        if wait and self.process.is_alive():
            try:
                self.tasks.send(None)
            except OSError:
                pass
            self.process.join(timeout=5)
        if self.process.is_alive():
            self.process.terminate()
            self.process.join(timeout=5)
        if self.process.is_alive():
            self.process.kill()
            self.process.join()
        self.tasks.close()
        self.results.close()


def _serve(fn, tasks, results, parent: int):
    """A worker's loop: run the tasks it is handed until told to stop or the main process is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    while os.getppid() == parent:
        if not tasks.poll(_POLL):
            continue
        try:
            item = tasks.recv()
        except EOFError:
            return
        if item is None:
            return
        index, task = item
        try:
            value = fn(task)
        except Exception as err:  # noqa: BLE001  (any error of one task is that task's failure)
            value = TaskFailed(f"{type(err).__name__}: {err}")
        results.send((index, value))
