"""Flight: the path a UAV flies through a plan's views, its metres and its turn-backs."""

from nbv.flight.path import FlightPath, azimuth_step, shell_path, shell_position
from nbv.flight.record import FLIGHT_FIELDS, flight_record, prefix_flight
from nbv.flight.reversals import azimuth_reversals
from nbv.flight.spread import pair_spreads_m, path_gap_m

__all__ = ["FLIGHT_FIELDS", "FlightPath", "azimuth_reversals", "azimuth_step", "flight_record",
           "pair_spreads_m", "path_gap_m", "prefix_flight", "shell_path", "shell_position"]
