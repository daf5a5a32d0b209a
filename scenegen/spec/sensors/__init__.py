"""Sensor kinds: the registry (:data:`SENSOR_KINDS`) of what a rig may hold, each kind with its
spec section, how its members sit in a rig and what it produces (docs/architecture.md, "Add a
sensor kind")."""
from scenegen.spec.sensors.kind import (LIGHT, MEMBER_KEYS, PRODUCTS, STREAM, VIEWS, RigFrame, SensorKind, SensorRun,
                                       stream_name)
from scenegen.spec.sensors.registry import SENSOR_KINDS, section_kinds

__all__ = ["LIGHT", "MEMBER_KEYS", "PRODUCTS", "SENSOR_KINDS", "STREAM", "VIEWS", "RigFrame", "SensorKind",
           "SensorRun", "section_kinds", "stream_name"]
