"""Both command lines, as a new user meets them: --version, every subcommand and option with a
help text (the parsers walked), -q / -v before or after the command."""
import argparse
import subprocess
import sys
from pathlib import Path

import pytest

import recon_eval
import scenegen
from recon_eval.cli import build_parser as recon_eval_parser
from scenegen.cli import build_parser as scenegen_parser

ROOT = Path(__file__).resolve().parents[1]


def _undocumented(parser: argparse.ArgumentParser, path: str) -> list[str]:
    bad = []
    for action in parser._actions:  # noqa: SLF001 (argparse has no public walk)
        if isinstance(action, argparse._HelpAction):  # noqa: SLF001
            continue
        name = "/".join(action.option_strings) or action.dest
        if isinstance(action, argparse._SubParsersAction):  # noqa: SLF001
            helps = {a.dest: a.help for a in action._choices_actions}  # noqa: SLF001
            for cmd, sub in action.choices.items():
                if not (helps.get(cmd) or "").strip():
                    bad.append(f"{path} {cmd}: no help")
                bad += _undocumented(sub, f"{path} {cmd}")
            continue
        if not (action.help or "").strip() or action.help == argparse.SUPPRESS:
            bad.append(f"{path} {name}: no help")
    return bad


@pytest.mark.parametrize("tool, parser", [("scenegen", scenegen_parser), ("recon-eval",
                                                                          lambda: recon_eval_parser(full=True))])
def test_every_command_and_option_has_help(tool, parser):
    bad = _undocumented(parser(), tool)
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("module, version", [("scenegen.cli", scenegen.__version__),
                                             ("recon_eval", recon_eval.__version__)])
def test_version(module, version):
    r = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0 and r.stdout.split()[-1] == version


def test_global_flags_before_and_after_the_command(capsys):
    from scenegen.cli import main

    spec = str(ROOT / "scenes/demo.yaml")
    for argv in (["-q", "validate", spec], ["validate", spec, "-q"], ["validate", "--quiet", spec]):
        assert main(argv) == 0
    assert main(["-v", "validate", spec]) == 0
    assert "scenegen validate:" in capsys.readouterr().err  # -v: the command's time
    from recon_eval.cli import parse_args

    for argv in (["-q", "cloud", "a", "b"], ["cloud", "a", "b", "-q"], ["cloud", "--quiet", "a", "b"]):
        assert parse_args(argv).quiet and not parse_args(argv).verbose
    assert parse_args(["cloud", "a", "b", "-v"]).verbose and parse_args(["--verbose", "cloud", "a", "b"]).verbose
    assert not parse_args(["cloud", "a", "b"]).quiet


def test_errors_are_one_line_and_verbose_adds_the_traceback(tmp_path):
    def run(*argv):
        return subprocess.run([sys.executable, "-m", "scenegen.cli", *argv], capture_output=True, text=True,
                              cwd=ROOT)

    r = run("info", str(tmp_path / "missing"))
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr
    r = run("-v", "info", str(tmp_path / "missing"))
    assert r.returncode == 2 and "Traceback" in r.stderr and r.stderr.strip().splitlines()[-1].startswith("scenegen: error:")
