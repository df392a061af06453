"""CCSDS TDM (503.0-B-2) KVN reader and writer (tqdyn.formats.tdm).

References: the standard's annex example E-1 (one-way Ka-band frequency
data of "yyyy-nnnA" at DSS-25, 2005-159), hand-written below from the
standard's text (abbreviated to its first three data lines); the values
read are compared with the text of the annex, not with the reader's output.
"""

from __future__ import annotations

import numpy as np
import pytest

from tqdyn.formats.tdm import Tdm, TdmSegment, format_tdm, parse_tdm, read_tdm, write_tdm

ANNEX_E1 = """CCSDS_TDM_VERS = 2.0
COMMENT TDM example created by yyyyy-nnnA Nav Team (NASA/JPL)
COMMENT StarTrek 1-way data, Ka band down
CREATION_DATE = 2005-160T20:15:00Z
ORIGINATOR = NASA
META_START
COMMENT Data quality degraded by antenna pointing problem...
COMMENT Slightly noisy data
TIME_SYSTEM = UTC
PARTICIPANT_1 = DSS-25
PARTICIPANT_2 = yyyy-nnnA
MODE = SEQUENTIAL
PATH = 2,1
INTEGRATION_INTERVAL = 1
INTEGRATION_REF = MIDDLE
FREQ_OFFSET = 0
TRANSMIT_DELAY_1 = 0.000077
RECEIVE_DELAY_1 = 0.000077
DATA_QUALITY = DEGRADED
META_STOP
DATA_START
COMMENT TRANSMIT_FREQ_2 is spacecraft reference downlink
TRANSMIT_FREQ_2 = 2005-159T17:41:00 32023442781.733
RECEIVE_FREQ_1 = 2005-159T17:41:00 32021034790.7265
RECEIVE_FREQ_1 = 2005-159T17:41:01 32021034828.8432
DATA_STOP
"""


def test_annex_example_is_read_as_the_standard_writes_it():
    """Annex E-1 of CCSDS 503.0-B-2: header, metadata and data as in its text."""
    tdm = parse_tdm(ANNEX_E1, "annex-E1")
    assert tdm.version == "2.0"
    assert tdm.comments == ["TDM example created by yyyyy-nnnA Nav Team (NASA/JPL)", "StarTrek 1-way data, Ka band down"]
    assert tdm.header == {"CREATION_DATE": "2005-160T20:15:00Z", "ORIGINATOR": "NASA"}
    (seg,) = tdm.segments
    assert seg.metadata["PARTICIPANT_1"] == "DSS-25" and seg.metadata["PATH"] == "2,1"
    assert seg.metadata["TRANSMIT_DELAY_1"] == "0.000077"
    assert seg.meta_comments[1] == "Slightly noisy data"
    epochs, f = seg.observations("RECEIVE_FREQ_1")
    assert epochs == ["2005-159T17:41:00", "2005-159T17:41:01"]
    assert f.tolist() == [32021034790.7265, 32021034828.8432]
    assert seg.observations("TRANSMIT_FREQ_2")[1].tolist() == [32023442781.733]


def test_round_trip_is_bit_equal(tmp_path):
    """write -> read -> write gives the same bytes, and the same message."""
    tdm = parse_tdm(ANNEX_E1, "annex-E1")
    tdm.segments.append(TdmSegment({"TIME_SYSTEM": "TDB", "PARTICIPANT_1": "TQ1", "PARTICIPANT_2": "TQ2",
                                     "MODE": "SEQUENTIAL", "PATH": "2,1", "RANGE_UNITS": "km"}, [],
                                    [("RANGE", "2035-01-01T00:00:00.000000", repr(1.7320508075688772e5))], []))
    a = write_tdm(tmp_path / "a.tdm", tdm)
    back = read_tdm(a)
    b = write_tdm(tmp_path / "b.tdm", back)
    assert a.read_bytes() == b.read_bytes()
    assert back == tdm
    assert float(back.segments[1].observations("RANGE")[1][0]) == 1.7320508075688772e5


@pytest.mark.parametrize("old,new,needle", [
    ("CCSDS_TDM_VERS = 2.0", "CCSDS_TDM_VERS = 3.0", "line 1: CCSDS_TDM_VERS"),
    ("ORIGINATOR = NASA", "ORIGINATOR_X = NASA", "line 5: ORIGINATOR_X"),
    ("PATH = 2,1", "PATHS = 2,1", "line 13: PATHS"),
    ("TIME_SYSTEM = UTC\n", "", "line 19: TIME_SYSTEM"),
    ("RECEIVE_FREQ_1 = 2005-159T17:41:01 32021034828.8432", "RECEIVE_FREQ_1 = 2005-159T17:41:01 3.2x10",
     "line 25: RECEIVE_FREQ_1"),
    ("RECEIVE_FREQ_1 = 2005-159T17:41:01 32021034828.8432", "RECEIVE_FREQ_1 = 17:41:01 32021034828.8432",
     "line 25: RECEIVE_FREQ_1"),
    ("RECEIVE_FREQ_1 = 2005-159T17:41:01 32021034828.8432", "RECEIVE_FREQ_9 = 2005-159T17:41:01 1.0",
     "line 25: RECEIVE_FREQ_9"),
    ("DATA_STOP\n", "", "line 25: DATA_STOP"),
])
def test_malformed_lines_are_refused_in_one_line(tmp_path, old, new, needle):
    """Each defect gives one line naming the file, the line and the field."""
    p = tmp_path / "bad.tdm"
    p.write_text(ANNEX_E1.replace(old, new, 1))
    with pytest.raises(ValueError) as err:
        read_tdm(p)
    msg = str(err.value)
    assert "\n" not in msg and str(p) in msg and needle in msg, msg


def test_failed_write_leaves_the_old_file(tmp_path):
    """A message that cannot be read back is refused before anything is written."""
    p = tmp_path / "x.tdm"
    p.write_text("old")
    bad = Tdm("2.0", {"CREATION_DATE": "2035-001T00:00:00", "ORIGINATOR": "TQ"}, [],
              [TdmSegment({"TIME_SYSTEM": "TDB"}, [], [("RANGE", "2035-001T00:00:00", "1.0")], [])])
    with pytest.raises(ValueError, match="PARTICIPANT_1"):
        write_tdm(p, bad)
    assert p.read_text() == "old" and sorted(x.name for x in tmp_path.iterdir()) == ["x.tdm"]
    assert format_tdm(bad).startswith("CCSDS_TDM_VERS = 2.0\n")
