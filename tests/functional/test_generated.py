"""The generated module packages of the examples import and run; skeletons never touch user code."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from specc.runtime import functional as rt
from specc.runtime.functional import Status
from tests.conftest import EXAMPLES, ROOT
from tests.functional.conftest import compile_robot


@pytest.fixture
def on_path(tmp_path: Path):  # type: ignore[no-untyped-def]
    added: list[str] = []

    def add(*folders: Path) -> None:
        for folder in folders:
            sys.path.insert(0, str(folder))
            added.append(str(folder))
    yield add
    for folder in added:
        sys.path.remove(folder)


def test_hilare_modules_run_with_their_codels(on_path) -> None:  # type: ignore[no-untyped-def]
    on_path(ROOT / "generated", EXAMPLES / "hilare")
    from hilare import modules  # type: ignore[import-not-found]
    from hilare.modules import loco  # type: ignore[import-not-found]

    registry = rt.Registry()
    made = modules.create_all(registry)
    assert set(made) == {"arm", "avoid", "explor", "loco", "pilo", "plan", "us", "visual"}
    registry.kernel.run_for(1.0)
    assert registry.incidents == []
    client = loco.client(made["loco"])
    robot = client.poster_Robot()
    assert robot is not None and robot.date == pytest.approx(0.985)  # CmdTask: 25 ms period, 10 ms delay
    assert client.final(client.GoTo(loco.Ref(x=1.0, v=0.2))).status is Status.END
    refused = client.final(client.GoTo(loco.Ref(v=99.0)))
    assert (refused.status, refused.report.code) == (Status.FINAL_ERROR, "BAD_REF_DATA")
    missing = client.final(client.Track("nowhere.Poster"))
    assert (missing.status, missing.report.code) == (Status.END, "POSTER_NOT_FOUND")
    with pytest.raises(LookupError, match="no poster 'Robott'"):
        client.poster("Robott")


def test_generic_system_of_table_3_1_compiles_and_runs(tmp_path: Path, on_path) -> None:  # type: ignore[no-untyped-def]
    name = compile_robot(EXAMPLES / "generic", tmp_path)
    on_path(tmp_path, EXAMPLES / "generic")
    package = __import__(f"{name}.modules", fromlist=["create_all"])
    registry = rt.Registry()
    made = package.create_all(registry)
    assert {"mod1", "mod2"} <= set(made)
    client = rt.ModuleClient(made["mod2"])
    running = client.send("mod2f1")
    assert client.interm(running).status is Status.WAITING
    assert client.call("mod2f3").status is Status.END  # Table 3.1: mod2f3 interrupts mod2's activities
    interrupted = client.final(running)
    assert (interrupted.status, interrupted.report.code) == (Status.INTERRUPTED, "mod2f3")


def test_missing_codel_module_is_a_clear_error(tmp_path: Path, on_path) -> None:  # type: ignore[no-untyped-def]
    spec = tmp_path / "lonely.spec"
    spec.write_text('module lonely {\n  codels: "lonely_codels";\n}\n')
    (tmp_path / "lonely_codels.py").write_text("")
    name = compile_robot(spec, tmp_path / "out")
    (tmp_path / "lonely_codels.py").unlink()  # the codels went missing after compilation
    on_path(tmp_path / "out")
    package = __import__(f"{name}.modules", fromlist=["create_all"])
    with pytest.raises(ImportError, match="cannot import its codels 'lonely_codels'"):
        package.create_all(rt.Registry())


def test_skeleton_adds_only_missing_codels_and_keeps_user_code(tmp_path: Path) -> None:
    spec = tmp_path / "arm.spec"
    spec.write_text('module arm {\n  codels: "arm_codels.arm";\n  request Grab {\n    type: exec;\n'
                    '    validate: checkGrab;\n    task: T;\n    fail: SLIP;\n    codel start: openGripper;\n'
                    '    codel exec: closeGripper -> exec, ether;\n  }\n  exec_task T {\n    period: 10 ms;\n'
                    '    codel permanent: watch;\n  }\n}\n')
    codels = tmp_path / "arm_codels"
    codels.mkdir()
    user = 'def openGripper(sdi, request):\n    # my own code, kept as written\n    return "exec"\n'
    (codels / "arm.py").write_text(user)

    def skeleton() -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "specc.cli", "skeleton", str(spec)], capture_output=True,
                              text=True, timeout=60)

    first = skeleton()
    assert first.returncode == 0, first.stderr
    assert "checkGrab, closeGripper, watch" in first.stdout
    text = (codels / "arm.py").read_text()
    assert text.startswith(user)
    assert text.count("def openGripper") == 1 and 'def closeGripper(sdi, request):' in text
    assert "return \"ether\"" in text.split("def closeGripper")[1].split("def ")[0]
    assert skeleton().stdout.strip() == "every function named by the specs already exists"
    assert (codels / "arm.py").read_text() == text
    check = subprocess.run([sys.executable, "-m", "specc.cli", "check", str(spec)], capture_output=True, text=True,
                           timeout=60)
    assert check.returncode == 0, check.stderr


def test_skeleton_covers_executive_functions_prs_actions_and_evaluable_predicates(tmp_path: Path) -> None:
    """Every function the specs name gets a stub, so a robot written from scratch checks at once."""
    spec = tmp_path / "shop.spec"
    spec.write_text('module arm {\n  codels: "arm_codels";\n  request Go { type: control; input: x: double;'
                    ' validate: checkGo; }\n}\n'
                    'executive shop {\n  codels: "shop_io";\n  service GO { request: arm.Go; input: where_to;'
                    ' output: how_it_went; }\n}\n'
                    'procedures tasks {\n  action SEND(service: {GO}) -> int = "task_codels.send";\n'
                    '  predicate evaluable READY(lambda: {LEFT, RIGHT}) = "task_codels.ready";\n'
                    '  ka Send { invocation: !(SEND-GO $ID); action: (SEND GO) -> $ID; }\n}\n')
    check = [sys.executable, "-m", "specc.cli", "check", str(spec)]
    before = subprocess.run(check, capture_output=True, text=True, timeout=60)
    assert before.returncode == 1 and "[missing-python-module]" in before.stdout + before.stderr
    wrote = subprocess.run([sys.executable, "-m", "specc.cli", "skeleton", str(spec)], capture_output=True,
                           text=True, timeout=60)
    assert wrote.returncode == 0, wrote.stderr
    assert "shop_io.py: where_to, how_it_went" in wrote.stdout and "task_codels.py: send, ready" in wrote.stdout
    tasks = (tmp_path / "task_codels.py").read_text()
    assert "def send(ctx, service):" in tasks and "def ready(ctx, lambda_):" in tasks
    after = subprocess.run(check, capture_output=True, text=True, timeout=60)
    assert after.returncode == 0, after.stdout + after.stderr


def test_skeleton_of_a_robot_folder_writes_new_codels_where_the_run_imports_them(tmp_path: Path) -> None:
    """Specs in a subfolder (modules/): the codels package a run imports is the robot folder's."""
    robot = tmp_path / "robot"
    (robot / "modules").mkdir(parents=True)
    (robot / "modules" / "arm.spec").write_text('module arm {\n  codels: "robot_codels.arm";\n  request Go {\n'
                                                '    type: control;\n    validate: checkGo;\n  }\n}\n')
    (robot / "robot.spec").write_text("system robot { modules: arm; }\n")
    # Given the folder above the robot's: the robot's folder is the one holding its system block.
    wrote = subprocess.run([sys.executable, "-m", "specc.cli", "skeleton", str(tmp_path)], capture_output=True,
                           text=True, timeout=60)
    assert wrote.returncode == 0, wrote.stderr
    assert "def checkGo(" in (robot / "robot_codels" / "arm.py").read_text()
    assert (robot / "robot_codels" / "__init__.py").exists() and not (robot / "modules" / "robot_codels").exists()
