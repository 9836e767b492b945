//! QGroundControl `.plan` files (docs/missions.md#plans-from-qgroundcontrol, Choice 159): a survey planned in the tool
//! teams use, read as the waypoints of a mission, and written back.
//!
//! A `.plan` is JSON; its `mission.items` are MAVLink mission items. The waypoints are the
//! `SimpleItem`s with command 16 (`MAV_CMD_NAV_WAYPOINT`): `params[4]` latitude in [−90, 90],
//! `params[5]` longitude (degrees, any finite value: wrapped), `params[6]` altitude (m) in the
//! item's `frame` (**Choice 300**: a `MAV_FRAME`; 0 and 5 above mean sea level, 3 and 6 relative
//! to the home's altitude; terrain-relative and local frames are refused by item, since the
//! mission has no terrain model). The local origin is `mission.plannedHomePosition`
//! [lat, lon, alt (AMSL)], at least [`pole_margin_degrees`] from a pole (**Choice 301**). Other
//! items (takeoff, loiter, camera, survey patterns) are refused by index, so nothing is silently
//! dropped. Waypoint `i` is `mission.items[i]`: every refusal names the item.
//!
//! **Geodetic → NED** (Choice 159): the flat-earth tangent plane at the origin on the WGS-84
//! ellipsoid, north = Δφ·R_M(φ₀), east = Δλ·R_N(φ₀)·cos φ₀ (Δλ wrapped to [−180°, 180°], so a
//! leg across the antimeridian is its short way round), down = −(alt − alt₀) — the meridian
//! and prime-vertical radii of curvature at the origin's latitude. Against the true local
//! tangent plane (WGS-84 ECEF → NED at the origin) it misplaces a point at horizontal distance
//! d by at most [`Origin::flat_earth_error`] = (d²/R_M)·√(1/4 + tan²φ₀/3) to leading order
//! (**Choice 302**): the surface's drop d²/(2R) below the plane, and the parallels' convergence
//! e·n·tan φ₀/R east and e²·tan φ₀/(2R) north. The inverse is exact for the same formulas, so
//! import → export → import returns the same points.

use controller_core::controller::MAX_POSITION;
use controller_core::readable::Readable;
use serde_json::{json, Value};
use thiserror::Error;

/// WGS-84 semi-major axis (m).
const WGS84_A: f64 = 6_378_137.0;
/// WGS-84 first eccentricity squared.
const WGS84_E2: f64 = 6.694_379_990_14e-3;
/// `MAV_CMD_NAV_WAYPOINT`.
const NAV_WAYPOINT: u64 = 16;

/// What a `.plan` cannot be read as; every message names the JSON key or the plan item.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PlanError {
    /// The text is not JSON (the parser's message: line and column).
    #[error("not JSON: {0}")]
    NotJson(String),
    /// JSON, but not a QGroundControl plan.
    #[error("fileType is not \"Plan\" (not a QGroundControl plan)")]
    NotPlan,
    /// A key of the plan (`mission.items[3].params[4] (latitude)`) and what is wrong with it.
    #[error("{key}: {message}")]
    Key { key: String, message: String },
}

fn key_error(key: impl Into<String>, message: impl Into<String>) -> PlanError {
    PlanError::Key {
        key: key.into(),
        message: message.into(),
    }
}

/// The plan item of waypoint `i`: `mission.items[i]` (every item is a waypoint).
pub fn item(i: usize) -> String {
    format!("mission.items[{i}]")
}

/// Why a point cannot be the origin of a mission frame.
#[derive(Clone, Copy, Debug, PartialEq, Error)]
pub enum OriginError {
    /// NaN or infinite.
    #[error("must be finite numbers")]
    NonFinite,
    /// A latitude outside [−90, 90].
    #[error("latitude {} is outside [-90, 90]", Readable(*.0))]
    Latitude(f64),
    /// Within [`pole_margin_degrees`] of a pole (Choice 301).
    #[error(
        "latitude {} is within {:.3}° of a pole: the tangent plane's east is undefined there, and \
         the ±{} m the controller reaches from its origin would cross the pole",
        Readable(*.0),
        pole_margin_degrees(),
        MAX_POSITION
    )]
    NearPole(f64),
}

/// How close to a pole an origin may be (degrees; **Choice 301**): the controller accepts
/// positions within ±[`MAX_POSITION`] of the mission origin along each axis, so a mission
/// reaches √2·MAX_POSITION (14.1 km) horizontally; over the smallest meridian radius
/// a(1 − e²) that is 0.128° of latitude. An origin farther from the pole keeps the pole (where
/// east is undefined and the plane's longitudes diverge as 1/cos φ) out of every mission's reach.
pub fn pole_margin_degrees() -> f64 {
    let reach = std::f64::consts::SQRT_2 * f64::from(MAX_POSITION);
    (reach / (WGS84_A * (1.0 - WGS84_E2))).to_degrees()
}

/// A longitude in [−180, 180] (degrees): itself if it is, else wrapped by whole turns.
pub fn wrap_longitude(lon: f64) -> f64 {
    if (-180.0..=180.0).contains(&lon) {
        lon
    } else {
        (lon + 180.0).rem_euclid(360.0) - 180.0
    }
}

/// A latitude and longitude (degrees) brought onto the globe (RFC 7946's ranges): a latitude
/// past a pole continues down the other side, half a turn round in longitude.
pub fn on_the_globe(lat: f64, lon: f64) -> [f64; 2] {
    if (-90.0..=90.0).contains(&lat) {
        return [lat, wrap_longitude(lon)];
    }
    let t = (lat + 90.0).rem_euclid(360.0);
    if t <= 180.0 {
        [t - 90.0, wrap_longitude(lon)]
    } else {
        [270.0 - t, wrap_longitude(lon + 180.0)]
    }
}

/// The local origin: latitude, longitude (degrees), altitude (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    pub lat: f64,
    pub lon: f64,
    pub alt: f64,
}

impl Origin {
    /// An origin: finite, the latitude in [−90, 90] and not within [`pole_margin_degrees`] of
    /// a pole (Choice 301), the longitude wrapped to [−180, 180].
    pub fn new(lat: f64, lon: f64, alt: f64) -> Result<Origin, OriginError> {
        if !(lat.is_finite() && lon.is_finite() && alt.is_finite()) {
            return Err(OriginError::NonFinite);
        }
        if lat.abs() > 90.0 {
            return Err(OriginError::Latitude(lat));
        }
        if lat.abs() > 90.0 - pole_margin_degrees() {
            return Err(OriginError::NearPole(lat));
        }
        Ok(Origin {
            lat,
            lon: wrap_longitude(lon),
            alt,
        })
    }

    /// The meridian and prime-vertical radii of curvature at the origin (m).
    fn radii(&self) -> (f64, f64) {
        let s = self.lat.to_radians().sin();
        let w = 1.0 - WGS84_E2 * s * s;
        (
            WGS84_A * (1.0 - WGS84_E2) / (w * w.sqrt()),
            WGS84_A / w.sqrt(),
        )
    }

    /// A geodetic point as NED [north, east, down] (m) in the tangent plane at the origin,
    /// `alt` above mean sea level; the longitude difference the short way round.
    pub fn to_ned(&self, lat: f64, lon: f64, alt: f64) -> [f64; 3] {
        let (rm, rn) = self.radii();
        [
            (lat - self.lat).to_radians() * rm,
            wrap_longitude(lon - self.lon).to_radians() * rn * self.lat.to_radians().cos(),
            -(alt - self.alt),
        ]
    }

    /// The inverse of [`Origin::to_ned`]: [lat, lon, alt], the longitude wrapped to [−180, 180].
    pub fn to_geodetic(&self, ned: [f64; 3]) -> [f64; 3] {
        let (rm, rn) = self.radii();
        [
            self.lat + (ned[0] / rm).to_degrees(),
            wrap_longitude(self.lon + (ned[1] / (rn * self.lat.to_radians().cos())).to_degrees()),
            self.alt - ned[2],
        ]
    }

    /// How far the flat-earth plane misplaces a point `d` metres (horizontally) from the
    /// origin, at most over its bearing, against the true tangent plane (m; **Choice 302**):
    /// (d²/R_M)·√(1/4 + tan²φ₀/3), the leading order (its next term is d/R smaller).
    pub fn flat_earth_error(&self, d: f64) -> f64 {
        let (rm, _) = self.radii();
        let t = self.lat.to_radians().tan();
        d * d / rm * (0.25 + t * t / 3.0).sqrt()
    }
}

/// How an item's altitude is read (its `frame`, a `MAV_FRAME`; Choice 300).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AltitudeFrame {
    /// `MAV_FRAME_GLOBAL` (0), `MAV_FRAME_GLOBAL_INT` (5): above mean sea level.
    MeanSeaLevel,
    /// `MAV_FRAME_GLOBAL_RELATIVE_ALT` (3), `…_INT` (6): above the home position.
    RelativeToHome,
}

impl AltitudeFrame {
    fn of(item: &Value, at: &str) -> Result<AltitudeFrame, PlanError> {
        match item["frame"].as_u64() {
            Some(0 | 5) => Ok(AltitudeFrame::MeanSeaLevel),
            Some(3 | 6) => Ok(AltitudeFrame::RelativeToHome),
            Some(f @ (10 | 11)) => Err(key_error(
                format!("{at}.frame"),
                format!(
                    "{f} (altitude above terrain) cannot be flown: the mission has no terrain \
                     model; give the altitude relative to home (frame 3) or above mean sea level \
                     (frame 0)"
                ),
            )),
            _ => Err(key_error(
                format!("{at}.frame"),
                format!(
                    "{} is not a global frame this import reads: give 3 (altitude relative to \
                     home) or 0 (above mean sea level)",
                    item["frame"]
                ),
            )),
        }
    }
}

/// The origin and the waypoints (NED, m; waypoint i is `mission.items[i]`) of a `.plan` text.
pub fn import(text: &str) -> Result<(Origin, Vec<[f64; 3]>), PlanError> {
    let v: Value = serde_json::from_str(text).map_err(|e| PlanError::NotJson(e.to_string()))?;
    if v["fileType"] != "Plan" {
        return Err(PlanError::NotPlan);
    }
    const HOME: &str = "mission.plannedHomePosition";
    let home = v["mission"]["plannedHomePosition"]
        .as_array()
        .filter(|a| a.len() == 3)
        .ok_or_else(|| key_error(HOME, "must be [lat, lon, alt]"))?;
    let num = |x: &Value, key: String| {
        x.as_f64()
            .filter(|f| f.is_finite())
            .ok_or_else(|| key_error(key, format!("must be a finite number, got {x}")))
    };
    let origin = Origin::new(
        num(&home[0], format!("{HOME}[0] (latitude)"))?,
        num(&home[1], format!("{HOME}[1] (longitude)"))?,
        num(&home[2], format!("{HOME}[2] (altitude)"))?,
    )
    .map_err(|e| key_error(HOME, e.to_string()))?;
    let items = v["mission"]["items"]
        .as_array()
        .ok_or_else(|| key_error("mission.items", "must be a list"))?;
    let mut points = Vec::with_capacity(items.len());
    for (i, it) in items.iter().enumerate() {
        let at = item(i);
        if it["type"] != "SimpleItem" || it["command"].as_u64() != Some(NAV_WAYPOINT) {
            return Err(key_error(
                &at,
                format!(
                    "only waypoints (a SimpleItem with command 16) are flown; this is {}",
                    what_item(it)
                ),
            ));
        }
        let frame = AltitudeFrame::of(it, &at)?;
        let p = it["params"]
            .as_array()
            .filter(|p| p.len() == 7)
            .ok_or_else(|| key_error(format!("{at}.params"), "must have 7 entries"))?;
        let lat = num(&p[4], format!("{at}.params[4] (latitude)"))?;
        let lon = num(&p[5], format!("{at}.params[5] (longitude)"))?;
        let alt = num(&p[6], format!("{at}.params[6] (altitude)"))?;
        if lat.abs() > 90.0 {
            return Err(key_error(
                format!("{at}.params[4] (latitude)"),
                format!("{} is outside [-90, 90]", Readable(lat)),
            ));
        }
        let [north, east, _] = origin.to_ned(lat, lon, origin.alt);
        let down = match frame {
            AltitudeFrame::MeanSeaLevel => -(alt - origin.alt),
            AltitudeFrame::RelativeToHome => -alt,
        };
        points.push([north, east, down]);
    }
    Ok((origin, points))
}

/// An item that is not a waypoint, in words: its type and command as the plan has them, or
/// that it has none.
fn what_item(it: &Value) -> String {
    let part = |key: &str| match &it[key] {
        Value::Null => format!("no {key}"),
        Value::String(s) => format!("{key} {s:?}"),
        other => format!("{key} {other}"),
    };
    match (&it["type"], &it["complexItemType"]) {
        (Value::String(t), Value::String(c)) if t == "ComplexItem" => {
            format!("a ComplexItem ({c:?}: a pattern QGroundControl expands into waypoints; convert it to waypoints in QGroundControl first)")
        }
        _ => format!("a {} with {}", part("type"), part("command")),
    }
}

/// A `.plan` text of the waypoints `points` (NED, m) around `origin`: what [`import`] reads
/// (frame 3, the altitude relative to home).
pub fn export(origin: &Origin, points: &[[f64; 3]]) -> String {
    let items: Vec<Value> = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let [lat, lon, _] = origin.to_geodetic(*p);
            json!({
                "type": "SimpleItem",
                "command": NAV_WAYPOINT,
                "frame": 3,
                "autoContinue": true,
                "doJumpId": i + 1,
                "params": [0, 0, 0, null, lat, lon, -p[2]],
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
/// per RFC 7946 (depth as a negative altitude): a flown path on a map. Every position is on
/// the globe ([`on_the_globe`]: latitude in [−90, 90], longitude in [−180, 180], Choice 301);
/// a non-finite sample (no position) is left out.
pub fn geojson_line(origin: &Origin, name: &str, path: &[[f64; 3]]) -> String {
    let coords: Vec<Value> = path
        .iter()
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .map(|p| {
            let [lat, lon, alt] = origin.to_geodetic(*p);
            let [lat, lon] = on_the_globe(lat, lon);
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
