//! Unit tests.

use super::*;
use crate::surface::{BezierPatch, Cylinder, Disk, Side, Sphere};
use crate::vec3::vec3;

#[test]
fn mixed_self_facing_is_found_on_saddles_only() {
    // z = (x − ½)(y − ½): bilinear, so the bicubic control net holds it exactly.
    let mut control = [[vec3(0.0, 0.0, 0.0); 4]; 4];
    for (i, row) in control.iter_mut().enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            let (x, y) = (i as f64 / 3.0, j as f64 / 3.0);
            *c = vec3(x, y, (x - 0.5) * (y - 0.5));
        }
    }
    let saddle = BezierPatch::new(control).unwrap();
    assert!(faces_itself_mixed(&Patch::whole(&saddle).unwrap()));
    let o = vec3(0.0, 0.0, 0.0);
    let z = vec3(0.0, 0.0, 1.0);
    let tube = Cylinder::new(o, z, 0.5, 1.0, Side::Inner).unwrap();
    let outside = Cylinder::new(o, z, 0.5, 1.0, Side::Outer).unwrap();
    let ball = Sphere::inner(o, 1.0).unwrap();
    let disk = Disk::new(o, z, 1.0).unwrap();
    let quarter = |s: &dyn Surface<f64>| {
        let r = Patch::whole(s).unwrap().rect();
        !faces_itself_mixed(&Patch::new(s, r.cell(0, 0, 4, 2)).unwrap())
    };
    assert!(quarter(&tube) && quarter(&outside) && quarter(&ball) && quarter(&disk));
}
