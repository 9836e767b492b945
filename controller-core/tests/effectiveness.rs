//! Thruster geometry and the effectiveness matrix B (`controller_core::effectiveness`,
//! docs/thrusters.md#geometry-and-the-effectiveness-matrix): the default layout is the documented choice, B is checked column by
//! column against r × d worked out by hand, and bad geometries are rejected with their numbers.

use controller_core::allocation::{AllocationError, PseudoInverse};
use controller_core::effectiveness::{
    GeometryError, ThrusterGeometry, AUV150_REVERSED, HORZ_AFT, HORZ_FORE, MAIN, THRUSTERS,
    VERT_AFT, VERT_FORE,
};

#[test]
fn default_layout_is_the_spec_choice() {
    // Positions docs/thrusters.md#geometry-and-the-effectiveness-matrix; mounting docs/real-vehicle.md#the-default-mounting: vertical fore pushing up (−z), aft down (+z),
    // horizontal pair pushing to port (−y), main forward.
    let g = ThrusterGeometry::default();
    assert_eq!(g.position[MAIN], [-2.43, 0.0, 0.0]);
    assert_eq!(g.direction[MAIN], [1.0, 0.0, 0.0]);
    assert_eq!(g.position[VERT_FORE], [1.8, 0.0, 0.0]);
    assert_eq!(g.position[VERT_AFT], [-1.8, 0.0, 0.0]);
    assert_eq!(g.direction[VERT_FORE], [0.0, 0.0, -1.0]);
    assert_eq!(g.direction[VERT_AFT], [0.0, 0.0, 1.0]);
    assert_eq!(g.position[HORZ_FORE], [1.8, 0.0, 0.0]);
    assert_eq!(g.position[HORZ_AFT], [-1.8, 0.0, 0.0]);
    assert_eq!(g.direction[HORZ_FORE], [0.0, -1.0, 0.0]);
    assert_eq!(g.direction[HORZ_AFT], [0.0, -1.0, 0.0]);
    assert_eq!(THRUSTERS, 5);
    assert_eq!(g, ThrusterGeometry::auv150(AUV150_REVERSED));
    assert_eq!(g.auv150_reversed(), Some(AUV150_REVERSED));
    // Every thruster along its reference axis.
    let r = ThrusterGeometry::auv150(0);
    assert_eq!(r.direction[VERT_AFT], [0.0, 0.0, 1.0]);
    assert_eq!(r.direction[HORZ_FORE], [0.0, 1.0, 0.0]);
    // A geometry that is not the AUV-150 layout has no mask.
    let mut tilted = g;
    tilted.direction[MAIN] = [0.6, 0.8, 0.0];
    assert_eq!(tilted.auv150_reversed(), None);
    let mut moved = g;
    moved.position[MAIN][0] = -2.0;
    assert_eq!(moved.auv150_reversed(), None);
}

#[test]
fn effectiveness_matrix_by_hand() {
    // Columns [d; r × d] by hand, rows X Y Z K M N: r × d for r = (x, 0, 0) is
    // (0, −x d_z, x d_y). Along the reference axes (+x, +z, +z, +y, +y):
    let reference: [[f32; 6]; THRUSTERS] = [
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],  // main: on the x axis, no moment
        [0.0, 0.0, 1.0, 0.0, -1.8, 0.0], // vertical fore: M = −1.8·T
        [0.0, 0.0, 1.0, 0.0, 1.8, 0.0],  // vertical aft: M = +1.8·T
        [0.0, 1.0, 0.0, 0.0, 0.0, 1.8],  // horizontal fore: N = +1.8·T
        [0.0, 1.0, 0.0, 0.0, 0.0, -1.8], // horizontal aft: N = −1.8·T
    ];
    // The real vehicle (default): the vertical fore and both horizontal tunnels reversed,
    // their columns negated.
    let default: [[f32; 6]; THRUSTERS] = [
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, -1.0, 0.0, 1.8, 0.0],  // pushing up fore: nose up
        [0.0, 0.0, 1.0, 0.0, 1.8, 0.0],   // pushing down aft: nose up
        [0.0, -1.0, 0.0, 0.0, 0.0, -1.8], // pushing to port fore: nose to port
        [0.0, -1.0, 0.0, 0.0, 0.0, 1.8],
    ];
    for (g, want) in [
        (ThrusterGeometry::auv150(0), reference),
        (ThrusterGeometry::default(), default),
    ] {
        let b = g.effectiveness().expect("AUV-150 layout accepted");
        for (c, col) in want.iter().enumerate() {
            for (r, &w) in col.iter().enumerate() {
                assert_eq!(b[(r, c)], w, "B[{r},{c}]");
            }
        }
        // The allocation keeps this very matrix.
        let a = PseudoInverse::new(&g).expect("AUV-150 layout accepted");
        assert_eq!(a.matrix(), b);
    }
}

#[test]
fn rejects_non_unit_direction() {
    let mut g = ThrusterGeometry::default();
    g.direction[VERT_FORE] = [0.0, 0.0, 2.0];
    let err = g.effectiveness().expect_err("non-unit direction");
    assert_eq!(
        err,
        GeometryError::NotUnitDirection {
            thruster: VERT_FORE,
            norm_squared: 4.0
        }
    );
    assert!(err.to_string().contains("thruster 1"), "{err}");
    // The allocation refuses the geometry with the same error and message.
    let alloc_err = PseudoInverse::new(&g).expect_err("non-unit direction");
    assert_eq!(alloc_err, AllocationError::Geometry(err));
    assert_eq!(alloc_err.to_string(), err.to_string());
    // Within the 1e-3 tolerance: accepted; just outside: rejected.
    g.direction[VERT_FORE] = [0.0, 0.0, 1.0009];
    assert!(g.effectiveness().is_ok());
    g.direction[VERT_FORE] = [0.0, 0.0, 0.9985];
    assert!(matches!(
        g.effectiveness(),
        Err(GeometryError::NotUnitDirection { thruster: 1, .. })
    ));
}

#[test]
fn rejects_non_finite_geometry() {
    let mut g = ThrusterGeometry::default();
    g.position[VERT_AFT][0] = f32::NAN;
    assert_eq!(
        g.effectiveness(),
        Err(GeometryError::NonFinite { thruster: VERT_AFT })
    );
    let mut g = ThrusterGeometry::default();
    g.direction[MAIN][1] = f32::INFINITY;
    assert_eq!(
        g.effectiveness(),
        Err(GeometryError::NonFinite { thruster: MAIN })
    );
    assert_eq!(
        PseudoInverse::new(&g),
        Err(AllocationError::Geometry(GeometryError::NonFinite {
            thruster: MAIN
        }))
    );
}

/// The mounting in words says, for every mask and thruster, which way the geometry's
/// direction pushes: ±x forward/aft, ±z down/up, ±y starboard/port.
#[test]
fn mounting_words_follow_the_directions_of_every_mask() {
    use controller_core::effectiveness::{mounting_words, Mounting, THRUSTER_NAMES};
    for mask in 0..32u8 {
        let g = ThrusterGeometry::auv150(mask);
        let words = mounting_words(mask);
        for (i, d) in g.direction.iter().enumerate() {
            let expected = match d {
                [x, _, _] if *x > 0.5 => "forward",
                [x, _, _] if *x < -0.5 => "aft",
                [_, _, z] if *z > 0.5 => "down",
                [_, _, z] if *z < -0.5 => "up",
                [_, y, _] if *y > 0.5 => "starboard",
                _ => "port",
            };
            assert_eq!(words[i], expected, "mask {mask:05b}, {}", THRUSTER_NAMES[i]);
        }
    }
    assert_eq!(
        Mounting(AUV150_REVERSED).to_string(),
        "main forward, vert fore up, vert aft down, horz fore port, horz aft port"
    );
}
