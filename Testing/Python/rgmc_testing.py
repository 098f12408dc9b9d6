"""What the Python tests share: the list of failed checks, and running a command with its output
shown in the test's log."""

import subprocess
import sys

failures = []


def check(condition, what):
    """Records `what` as a failure unless `condition` holds; says so on stderr."""
    if not condition:
        failures.append(what)
        print("FAILED: %s" % what, file=sys.stderr)


def run(command, timeout=900, env=None, tail=None):
    """Runs `command`, prints it and its output (the last `tail` characters of each stream when
    given), and returns the finished process."""
    print("+ " + " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=env)
    print(result.stdout[-tail:] if tail else result.stdout)
    print(result.stderr[-tail:] if tail else result.stderr, file=sys.stderr)
    return result
