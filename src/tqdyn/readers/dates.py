"""Calendar checks of the date-time fields read from files (CCSDS TDM epochs, SP3 epochs): one
function, one phrase per fault, so that every reader refuses a date that does not exist the same way.

:func:`calendar_problem` says what is wrong with (year, month, day) or (year, day of year) and
(hour, minute, second) in a time scale, or returns None: month 01-12; day 01 to the length of the
month (Gregorian calendar: 28, 29, 30 or 31); day of year 001-365 (366 in a leap year); hour 00-23;
minute 00-59; second 0 <= s < 60, and 60 <= s < 61 only in UTC, in the minute 23:59 of a day that
ends with a leap second (:func:`leap_second_days`).  Scales without leap seconds (TT, TDB, TAI,
GPS time and the other GNSS times) never have a second 60.
"""

from __future__ import annotations

import calendar
import datetime

import erfa

__all__ = ["calendar_problem", "leap_second_days"]


def leap_second_days() -> dict:
    """UTC days that end with a leap second -> the leap second's length [s] (1.0 for all so far):
    the day before each step of TAI - UTC from 1972 on in ERFA's leap-second table, the table
    :mod:`tqdyn.astro.timescales` uses (it merges the IERS ``Leap_Second.dat`` into it on import).
    The steps before 1972 (UTC with a rate offset) have no second 60."""
    table = erfa.leap_seconds.get()
    out = {}
    for prev, row in zip(table[:-1], table[1:]):
        if int(prev["year"]) >= 1972:
            first = datetime.date(int(row["year"]), int(row["month"]), 1)
            out[first - datetime.timedelta(days=1)] = float(row["tai_utc"] - prev["tai_utc"])
    return out


def calendar_problem(year: int, month: int | None, day: int | None, hour: int, minute: int, second: float, *,
                     day_of_year: int | None = None, scale: str = "UTC") -> str | None:
    """None if the fields name an instant of the time scale ``scale``; else one phrase, ``"<field>
    <value> is not allowed; allowed: <range>"`` (module docstring).  Give either month and day, or
    ``day_of_year`` (month = day = None).  second [s] may carry a fraction."""
    if day_of_year is not None:
        top = 366 if calendar.isleap(year) else 365
        if not 1 <= day_of_year <= top:
            return f"day of year {day_of_year:03d} is not allowed; allowed: 001-{top} in {year:04d}"
        date = datetime.date(year, 1, 1) + datetime.timedelta(days=day_of_year - 1)
    else:
        if not 1 <= month <= 12:
            return f"month {month:02d} is not allowed; allowed: 01-12"
        top = calendar.monthrange(year, month)[1]
        if not 1 <= day <= top:
            return f"day {day:02d} is not allowed; allowed: 01-{top} in {year:04d}-{month:02d}"
        date = datetime.date(year, month, day)
    if not 0 <= hour <= 23:
        return f"hour {hour:02d} is not allowed; allowed: 00-23"
    if not 0 <= minute <= 59:
        return f"minute {minute:02d} is not allowed; allowed: 00-59"
    if 0 <= second < 60:
        return None
    if scale == "UTC" and hour == 23 and minute == 59 and 60 <= second < 60 + leap_second_days().get(date, 0.0):
        return None
    if scale == "UTC":
        return (f"second {second:g} is not allowed; allowed: 0 <= second < 60 (60.x only at 23:59 of a UTC day that "
                "ends with a leap second)")
    return f"second {second:g} is not allowed; allowed: 0 <= second < 60 ({scale} has no leap seconds)"
