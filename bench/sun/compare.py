"""Solar position: Campanile (NREL SPA, `process::sun`) against pvlib's
vectorized NREL SPA, on the same instants and sites, in the same run.

Writes the grid, times pvlib, reads Campanile's positions and rate (the
library, `sun_positions`, timed inside the process), times the CLI
(`campanile sun --csv IN --out OUT`, wall clock of the whole process: start,
CSV parsing and writing included), and prints the error and the throughput
ratio as Markdown table rows, library then CLI.
"""
import csv, subprocess, sys, time
import numpy as np
import pvlib
from pvlib import spa

M = int(sys.argv[1]) if len(sys.argv) > 1 else 200   # instants
S = int(sys.argv[2]) if len(sys.argv) > 2 else 50    # sites per instant (1: every row its own instant)
workdir = sys.argv[3]
campanile_bin = sys.argv[4]
cli_bin = sys.argv[5] if len(sys.argv) > 5 else None
N = M * S
rng = np.random.default_rng(20261122)

# Instants from 1950 to 2080, each at S sites spread over every latitude and
# longitude and a range of heights; rows grouped by instant.
t0 = np.datetime64("1950-01-01T00:00:00").astype("datetime64[s]").astype(np.int64)
t1 = np.datetime64("2080-12-31T23:59:59").astype("datetime64[s]").astype(np.int64)
unixtime = np.repeat(rng.integers(t0, t1, M), S).astype(np.float64)
lat = rng.uniform(-89.9, 89.9, N)
lon = rng.uniform(-180.0, 180.0, N)
elev = rng.uniform(0.0, 3000.0, N)
pressure = 1013.25 * np.exp(-elev / 8434.0)
temp = rng.uniform(-20.0, 35.0, N)
dt64 = unixtime.astype("datetime64[s]")
years = dt64.astype("datetime64[Y]").astype(int) + 1970
months = dt64.astype("datetime64[M]").astype(int) % 12 + 1
delta_t = spa.calculate_deltat(years, months)

grid = f"{workdir}/sun_grid.csv"
with open(grid, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["time_utc", "latitude_deg", "longitude_deg", "elevation_m", "pressure_mbar", "temperature_c", "delta_t_s"])
    for k in range(N):
        w.writerow([str(dt64[k]) + "Z", repr(float(lat[k])), repr(float(lon[k])), repr(float(elev[k])), repr(float(pressure[k])), repr(float(temp[k])), repr(float(delta_t[k]))])

def pvlib_run():
    return spa.solar_position_numpy(unixtime, lat, lon, elev, pressure, temp, delta_t, 0.5667, numthreads=1, sst=False, esd=False)

pvlib_run()
reps = 5
start = time.perf_counter()
for _ in range(reps):
    res = pvlib_run()
pv_rate = N * reps / (time.perf_counter() - start)
# pvlib returns (theta: apparent zenith, theta0: unrefracted zenith, e, e0, phi: azimuth, eot).
apparent_zenith, azimuth = res[0], res[4]

out = f"{workdir}/sun_campanile.csv"

rate = float(subprocess.check_output([campanile_bin, grid, out, "200"]).decode().strip())
ours = np.loadtxt(out, delimiter=",", skiprows=1)
dz = np.abs(ours[:, 0] - apparent_zenith)
da = np.abs((ours[:, 1] - azimuth + 180.0) % 360.0 - 180.0)
# Azimuth is ill-defined at the zenith: weight it by sin(zenith) (the angle on the sky).
da_sky = da * np.sin(np.radians(apparent_zenith))
print(f"| {M} instants × {S} sites = {N}, 1950–2080, all latitudes | pvlib {pvlib.__version__} `spa.solar_position_numpy` | "
      f"{dz.max():.2e}° | {da_sky.max():.2e}° (max az. {da.max():.2e}°) | {rate:,.0f} /s | {pv_rate:,.0f} /s | {rate / pv_rate:.1f}× |")

if cli_bin:
    cli_out = f"{workdir}/sun_cli.csv"
    walls = []
    for _ in range(3):
        start = time.perf_counter()
        subprocess.check_call([cli_bin, "sun", "--csv", grid, "--out", cli_out], stdout=subprocess.DEVNULL)
        walls.append(time.perf_counter() - start)
    wall = sorted(walls)[1]
    cli = np.loadtxt(cli_out, delimiter=",", skiprows=1, usecols=(7, 8))
    cz = np.abs(cli[:, 0] - apparent_zenith)
    ca = np.abs((cli[:, 1] - azimuth + 180.0) % 360.0 - 180.0) * np.sin(np.radians(apparent_zenith))
    print(f"| CLI `campanile sun --csv` (median of 3 runs, {wall * 1e3:.0f} ms wall; output to 1e-7°) | pvlib {pvlib.__version__} `spa.solar_position_numpy` | "
          f"{cz.max():.2e}° | {ca.max():.2e}° | {N / wall:,.0f} /s | {pv_rate:,.0f} /s | {N / wall / pv_rate:.1f}× |")
