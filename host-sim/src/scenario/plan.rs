//! QGroundControl `.plan` files (docs/missions.md#plans-from-qgroundcontrol, Choice 159): a survey planned in the tool
//! teams use, read as the waypoints of a mission, and written back.
//!
//! A `.plan` is JSON; its `mission.items` are MAVLink mission items. The waypoints are the
//! `SimpleItem`s with command 16 (`MAV_CMD_NAV_WAYPOINT`): `params[4]` latitude, `params[5]`
//! longitude (degrees), `params[6]` altitude (m, relative to the home position's altitude:
//! QGroundControl's default frame 3). The local origin is `mission.plannedHomePosition`
//! [lat, lon, alt]. Other items (takeoff, loiter, camera, survey patterns) are refused by name,
//! so nothing is silently dropped.
//!
//! **Geodetic → NED** (Choice 159): the flat-earth tangent plane at the origin on the WGS-84
//! ellipsoid, north = Δφ·R_M(φ₀), east = Δλ·R_N(φ₀)·cos φ₀, down = −(alt − alt₀) — the
//! meridian and prime-vertical radii of curvature at the origin's latitude. Its error grows as
//! d²/R with the distance d from the origin (the curvature the plane ignores): under 1 cm at
//! 250 m, 0.2 m at 1 km; a survey of a few hundred metres is well inside the 0.05 m bound. The
//! inverse is exact for the same formulas, so import → export → import returns the same points.

use serde_json::{json, Value};

/// WGS-84 semi-major axis (m).
const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 first eccentricity squared.
const WGS84_E2: f64 = 6.694_379_990_14e-3;
/// `MAV_CMD_NAV_WAYPOINT`.
const NAV_WAYPOINT: u64 = 16;

/// The local origin: latitude, longitude (degrees), altitude (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    pub lat: f64,
    pub lon: f64,
    pub alt: f64,
}

impl Origin {
    /// The meridian and prime-vertical radii of curvature at the origin (m).
    fn radii(&self) -> (f64, f64) {
        let s = self.lat.to_radians().sin();
        let w = 1.0 - WGS84_E2 * s * s;
        (
            WGS84_A * (1.0 - WGS84_E2) / (w * w.sqrt()),
            WGS84_A / w.sqrt(),
        )
    }

    /// A geodetic point as NED [north, east, down] (m) in the tangent plane at the origin.
    pub fn to_ned(&self, lat: f64, lon: f64, alt: f64) -> [f64; 3] {
        let (rm, rn) = self.radii();
        [
            (lat - self.lat).to_radians() * rm,
            (lon - self.lon).to_radians() * rn * self.lat.to_radians().cos(),
            -(alt - self.alt),
        ]
    }

    /// The inverse of [`Origin::to_ned`]: [lat, lon, alt].
    pub fn to_geodetic(&self, ned: [f64; 3]) -> [f64; 3] {
        let (rm, rn) = self.radii();
        [
            self.lat + (ned[0] / rm).to_degrees(),
            self.lon + (ned[1] / (rn * self.lat.to_radians().cos())).to_degrees(),
            self.alt - ned[2],
        ]
    }
}

/// The origin and the waypoints (NED, m) of a `.plan` text; the error says what is wrong and
/// where (`mission.items[3]: …`).
pub fn import(text: &str) -> Result<(Origin, Vec<[f64; 3]>), String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    if v["fileType"] != "Plan" {
        return Err("fileType is not \"Plan\" (not a QGroundControl plan)".into());
    }
    let home = v["mission"]["plannedHomePosition"]
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or("mission.plannedHomePosition must be [lat, lon, alt]")?;
    let num = |x: &Value, what: &str| {
        x.as_f64()
            .filter(|f| f.is_finite())
            .ok_or_else(|| format!("{what} must be a number"))
    };
    let origin = Origin {
        lat: num(&home[0], "mission.plannedHomePosition[0]")?,
        lon: num(&home[1], "mission.plannedHomePosition[1]")?,
        alt: num(&home[2], "mission.plannedHomePosition[2]")?,
    };
    let items = v["mission"]["items"]
        .as_array()
        .ok_or("mission.items must be a list")?;
    let mut points = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let at = format!("mission.items[{i}]");
        if item["type"] != "SimpleItem" || item["command"].as_u64() != Some(NAV_WAYPOINT) {
            return Err(format!(
                "{at}: only waypoints (SimpleItem, command 16) are flown; this is {} command {}",
                item["type"], item["command"]
            ));
        }
        let p = item["params"]
            .as_array()
            .filter(|p| p.len() == 7)
            .ok_or_else(|| format!("{at}.params must have 7 entries"))?;
        let lat = num(&p[4], &format!("{at}.params[4] (latitude)"))?;
        let lon = num(&p[5], &format!("{at}.params[5] (longitude)"))?;
        let alt = num(&p[6], &format!("{at}.params[6] (altitude)"))?;
        points.push(origin.to_ned(lat, lon, alt));
    }
    Ok((origin, points))
}

/// A `.plan` text of the waypoints `points` (NED, m) around `origin`: what [`import`] reads.
pub fn export(origin: &Origin, points: &[[f64; 3]]) -> String {
    let items: Vec<Value> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let [lat, lon, alt] = origin.to_geodetic(*p);
            json!({
                "type": "SimpleItem",
                "command": NAV_WAYPOINT,
                "frame": 3,
                "autoContinue": true,
                "doJumpId": i + 1,
                "params": [0, 0, 0, null, lat, lon, alt],
            })
        })
        .collect();
    let plan = json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": "host-sim",
        "geoFence": {"circles": [], "polygons": [], "version": 2},
        "rallyPoints": {"points": [], "version": 2},
        "mission": {
            "version": 2,
            "firmwareType": 12,
            "vehicleType": 12,
            "plannedHomePosition": [origin.lat, origin.lon, origin.alt],
            "items": items,
        },
    });
    serde_json::to_string_pretty(&plan).unwrap_or_default()
}

/// A GeoJSON `Feature` with the `LineString` of a path (NED, m) around `origin`, [lon, lat]
/// per RFC 7946 (depth as a negative altitude): a flown path on a map.
pub fn geojson_line(origin: &Origin, name: &str, path: &[[f64; 3]]) -> String {
    let coords: Vec<Value> = path
        .iter()
        .map(|p| {
            let [lat, lon, alt] = origin.to_geodetic(*p);
            json!([lon, lat, alt])
        })
        .collect();
    let f = json!({
        "type": "Feature",
        "properties": {"name": name},
        "geometry": {"type": "LineString", "coordinates": coords},
    });
    f.to_string()
}
