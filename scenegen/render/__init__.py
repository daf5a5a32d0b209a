"""The Mitsuba adapter: back-end selection, our camera model as a Mitsuba sensor, scene building,
and the truth pass. Everything that imports Mitsuba or Dr.Jit lives in this package."""
