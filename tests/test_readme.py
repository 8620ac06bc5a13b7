"""The README's two set-up commands are what users and CI run: keep them in step."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _bash_blocks(text):
    return [b.strip() for b in re.findall(r"```bash\n(.*?)```", text, flags=re.S)]


def test_ci_runs_the_readme_test_command():
    blocks = _bash_blocks((ROOT / "README.md").read_text())
    test_cmd = [b for b in blocks if "pytest" in b]
    assert len(test_cmd) == 1, "the README must show exactly one test command"
    ci = (ROOT / ".ci" / "run").read_text().splitlines()
    assert test_cmd[0] in ci, "the CI script must run the README's test command verbatim"


def test_readme_demo_command_names_an_existing_demo():
    from mutext.cli import _available_demos
    blocks = _bash_blocks((ROOT / "README.md").read_text())
    demo = [b for b in blocks if "mutext demo" in b]
    assert demo, "the README must show the demo command"
    name = re.search(r"mutext demo (\S+)", demo[0]).group(1)
    assert name in _available_demos()
