"""What every command shares: one --data-dir and one way to find a bag, the
subcommand's usage on a misspelt option, and help text without reST."""

import pytest

from vic_drake.cli import build_parser, main, subcommand_parser

#: Every command that reads a bag, with the arguments that reach the bag.
BAG_COMMANDS = {
    "fit-palpation": ["{bag}"],
    "load-test": ["{bag}", "--fit-from", "{bag}"],
    "fit-relaxation": ["{bag}"],
    "estimate-online": ["{bag}"],
    "replay-qp": ["{bag}"],
    "compare-real": ["{bag}"],
}


def fake_data_dir(root):
    """A folder check_data_dir accepts, holding one bag folder without its
    metadata.yaml (the reader then names the path it was given)."""
    (root / "phantom_map").mkdir(parents=True)
    (root / "phantom_map" / "z.txt").write_text("")
    (root / "experiments" / "fake_log").mkdir(parents=True)
    return root


def run(capsys, argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize("command", sorted(BAG_COMMANDS))
def test_every_bag_command_finds_a_relative_bag_in_the_data_dir(
    command, tmp_path, capsys, monkeypatch
):
    data = fake_data_dir(tmp_path / "data")
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    argv = [a.format(bag="experiments/fake_log") for a in BAG_COMMANDS[command]]
    status, _, err = run(capsys, [command, *argv, "--data-dir", data])
    assert status == 2, err
    # The reader got the bag inside the data folder (it has no metadata.yaml).
    assert f"{str(data / 'experiments' / 'fake_log')!r}" in err
    assert "no metadata.yaml" in err and "Traceback" not in err
    # The same through $VIC_DRAKE_DATA.
    monkeypatch.setenv("VIC_DRAKE_DATA", str(data))
    status, _, err = run(capsys, [command, *argv])
    assert status == 2 and "no metadata.yaml" in err


@pytest.mark.parametrize("command", sorted(BAG_COMMANDS))
def test_a_missing_bag_says_where_it_looked(command, tmp_path, capsys, monkeypatch):
    data = fake_data_dir(tmp_path / "data")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("VIC_DRAKE_DATA", str(data))
    argv = [a.format(bag="experiments/fake_lgo") for a in BAG_COMMANDS[command]]
    status, _, err = run(capsys, [command, *argv])
    assert status == 2
    assert "'experiments/fake_lgo' does not exist in the current folder" in err
    assert f"nor in the data folder {str(data)!r} ($VIC_DRAKE_DATA)" in err
    assert "did you mean 'experiments/fake_log'?" in err


def test_a_missing_bag_without_a_data_folder_says_how_to_name_one(
    tmp_path, capsys, monkeypatch
):
    import vic_drake.paths as paths

    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    monkeypatch.setattr(paths, "DEFAULT_DATA_DIR", tmp_path / "shared" / "data")
    status, _, err = run(capsys, ["fit-palpation", "palpation/test_soft_1hz"])
    assert status == 2
    assert "does not exist in the current folder" in err
    assert "there is no data folder" in err
    assert f"{str(tmp_path / 'shared' / 'data')!r} does not exist" in err
    assert "pass --data-dir DIR or set VIC_DRAKE_DATA" in err


def test_a_bad_data_dir_says_what_the_command_does_without(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    missing = tmp_path / "none"
    status, _, err = run(capsys, ["compare-real", "x", "--data-dir", missing])
    assert status == 2 and "synthetic phantom" not in err
    assert "this command needs the data" in err
    status, _, err = run(capsys, ["fit-palpation", "x", "--data-dir", missing])
    assert status == 2 and "omit the option to read bag paths only as given" in err
    status, _, err = run(capsys, ["scan", "x.yaml", "--data-dir", missing])
    assert status == 2 and "to run on the synthetic phantom" in err


@pytest.mark.parametrize(
    "argv, bad, hint",
    [
        (["reproduce", "--quik", "--out", "x"], "--quik", "--quick"),
        (["scan", "a.yaml", "--durration", "3"], "--durration 3", "--duration"),
        (["fit-palpation", "b", "--bettas", "1.1"], "--bettas 1.1", "--betas"),
        (["compare-real", "b", "--stifness=400"], "--stifness=400", "--stiffness"),
    ],
)
def test_a_misspelt_option_shows_the_subcommands_usage_and_the_closest(
    capsys, argv, bad, hint
):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith(f"usage: vic-drake {argv[0]} ")
    assert f"vic-drake {argv[0]}: error: unrecognized arguments: {bad}" in err
    assert f"(did you mean {hint}?)" in err


def test_an_extra_positional_shows_the_subcommands_usage(capsys):
    with pytest.raises(SystemExit):
        main(["replay-qp", "a", "b"])
    err = capsys.readouterr().err
    assert err.startswith("usage: vic-drake replay-qp ")
    assert err.rstrip().endswith("unrecognized arguments: b")


#: Every subcommand the parser has.
ALL_COMMANDS = tuple(build_parser().get_default("_subparsers").choices)


@pytest.mark.parametrize("command", ALL_COMMANDS)
def test_help_has_no_rest_markup(command):
    text = subcommand_parser(build_parser(), command).format_help()
    assert "``" not in text


def test_every_bag_command_has_the_one_data_dir_option():
    parser = build_parser()
    for command in BAG_COMMANDS:
        text = " ".join(subcommand_parser(parser, command).format_help().split())
        assert "--data-dir DIR the paper's measurements" in text, command
        assert "a relative BAG_DIR that is not in the current folder is read" in text


def test_the_r_weight_option_reads_alike():
    parser = build_parser()
    for command in ("replay-qp", "compare-real"):
        usage = subcommand_parser(parser, command).format_usage()
        assert "[--R R]" in usage, (command, usage)


def test_scan_help_describes_the_command_its_scenario_and_duration():
    text = " ".join(subcommand_parser(build_parser(), "scan").format_help().split())
    assert "Simulates one scenario file" in text
    assert "SCENARIO.yaml a scenario file: diagrams/*.yaml" in text
    assert "default: the scenario's duration_s, else its trajectory's end + 1 s" in text
    assert "peak_force_N is the tissue's force on the patient" in text


def test_a_misspelt_command_names_the_closest(capsys):
    from vic_drake.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["reproduc", "--quick", "--out", "x"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "unknown command 'reproduc' (did you mean reproduce?)" in err
    assert "compare-real" in err  # The commands are listed.


def test_ctrl_c_while_the_commands_load_is_no_traceback(monkeypatch, capsys):
    """Issue: a Ctrl-C in the first second (the parser imports the commands'
    modules) printed a traceback; it now ends as any other interruption."""
    from vic_drake import cli

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    assert cli.main(["campaign", "--help"]) == 130
    assert capsys.readouterr().err.strip() == "vic-drake: interrupted"


def test_allow_code_change_goes_with_resume(capsys, tmp_path):
    from pathlib import Path

    smoke = Path(__file__).resolve().parents[2] / "campaigns" / "smoke.yaml"
    status, _, err = run(
        capsys, ["campaign", smoke, "--out", tmp_path / "c", "--allow-code-change"]
    )
    assert status == 2
    assert "--allow-code-change goes with --resume" in err
    assert not (tmp_path / "c").exists()
