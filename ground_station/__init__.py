"""The ground station: fusion, the GNSS-localizability map, the MPCs and the control cycle."""
