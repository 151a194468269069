"""Pull-and-release records: `vibid.decay` gives back the closed form the records are built from
(frequency, damping, spring and mass), equals `vibid decay --json` on the same files, and on the
ECP cart's records gives the published frequencies, spring and cart mass."""
import os
import pathlib

import numpy as np
import pytest

import vibid
from conftest import ROOT, cli_json

K, M, DM, ZETA, FS = 800.0, 2.0, 1.0, 0.02, 200.0


def release_record(path, m_kg, seed):
    """A pull-and-release record of a mass m_kg on the spring K."""
    # At rest, pulled to 2 cm over 0.5 s, held 1 s, released at t = 2 s into the damped cosine
    # x = 0.02 exp(-zeta wn t) cos(wd t).
    wn = np.sqrt(K / m_kg)
    wd = wn * np.sqrt(1 - ZETA ** 2)
    t = np.arange(int(8 * FS)) / FS
    tr = t - 2.0
    x = np.where(tr < 0, np.clip((t - 0.5) / 0.5, 0, 1) * 0.02,
                 0.02 * np.exp(-ZETA * wn * tr) * np.cos(wd * tr))
    x += 1e-6 * np.random.default_rng(seed).standard_normal(t.size)
    vibid.Recording(names=["x1_m"], data=x[None, :], fs_hz=FS).write_csv(path)


@pytest.fixture
def records(tmp_path):
    base = [tmp_path / f"base{i}.csv" for i in range(2)]
    loaded = [tmp_path / f"loaded{i}.csv" for i in range(2)]
    for i, p in enumerate(base):
        release_record(p, M, i)
    for i, p in enumerate(loaded):
        release_record(p, M + DM, 10 + i)
    return base, loaded


def test_decay_equals_cli(records):
    base, loaded = records
    cli = cli_json("decay", *base, "--position", "x1_m", "--loaded", *loaded, "--added-kg", DM,
                   "--json")
    py = vibid.decay(base, position="x1_m", loaded=loaded, added_kg=DM)
    assert py.json == cli
    assert py.k_n_per_m == cli["k_n_per_m"] and len(py.records) == 2


def test_decay_gives_the_closed_form_of_the_records(records):
    # The records are the closed form x = 0.02 exp(-zeta wn t) cos(wd t) of a mass on the spring
    # K (release_record), with 1 um of noise on 2 cm: the fit gives back its parameters, and the
    # two masses give back the spring and the base mass: wn^2 = K / m, so K = DM / (1/wn_l^2 -
    # 1/wn_b^2) and m = K / wn_b^2.
    base, loaded = records
    py = vibid.decay(base, position="x1_m", loaded=loaded, added_kg=DM)
    wn = np.sqrt(K / M)  # 20 rad/s
    assert py.omega_n_rad_s == pytest.approx(wn, rel=1e-4)
    assert py.omega_d_rad_s == pytest.approx(wn * np.sqrt(1 - ZETA ** 2), rel=1e-4)
    assert py.zeta == pytest.approx(ZETA, rel=1e-3)
    assert py.json["loaded"]["omega_n_rad_s"] == pytest.approx(np.sqrt(K / (M + DM)), rel=1e-4)
    assert py.k_n_per_m == pytest.approx(K, rel=1e-3)
    assert py.base_mass_kg == pytest.approx(M, rel=1e-3)


def shared_data(folder):
    """The unlicensed records beside the project (../shared/data or $VIBID_SHARED_DATA): skipped
    when absent, failed instead with VIBID_REQUIRE_REAL_DATA=1, as the C++ tests do."""
    root = pathlib.Path(os.environ.get("VIBID_SHARED_DATA") or ROOT.parent / "shared" / "data")
    d = root / folder
    if not d.is_dir():
        why = f"no {d}: the {folder} records (no license) are read from ../shared/data"
        if os.environ.get("VIBID_REQUIRE_REAL_DATA") == "1":
            pytest.fail(why)
        pytest.skip(why)
    return d


def test_ecp_cart_against_the_published_values():
    d = shared_data("ecp_cart_free_decay")
    py = vibid.decay(sorted(d.glob("Khigh_load-none_*.csv")), position="X_cm:cm",
                     loaded=sorted(d.glob("Khigh_load-0.986kg_*.csv")), added_kg=0.986)
    # Published (ecp_cart_free_decay/README.md): 34.9066 and 21.2989 rad/s from one period at
    # 200 Hz, k 712.60 N/m, cart 0.5848 kg.
    assert py.omega_d_rad_s == pytest.approx(34.9066, rel=0.01)
    assert py.json["loaded"]["omega_d_rad_s"] == pytest.approx(21.2989, rel=0.01)
    assert py.k_n_per_m == pytest.approx(712.60, rel=0.01)
    assert py.base_mass_kg == pytest.approx(0.5848, rel=0.02)


def test_decay_refusals_are_the_clis(records):
    base, loaded = records
    with pytest.raises(ValueError, match="--loaded needs --added-kg"):
        vibid.decay(base, position="x1_m", loaded=loaded)
    with pytest.raises(ValueError, match="x9_m"):
        vibid.decay(base, position="x9_m")
