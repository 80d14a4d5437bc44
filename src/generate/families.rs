//! The shape families: how each family turns seeded parameters into a [`Model`] of parts.

use super::Family;
use super::sdf::{
    IDENTITY, Model, Params, Part, Primitive, V3, add, mat_mul, mat_vec, rotation, scale,
};

const DOWN: V3 = [0.0, -1.0, 0.0];

/// How many times a colliding pose is redrawn before it is accepted anyway.
const MAX_REDRAWS: usize = 50;

/// A limb segment that must stay clear of the other parts (the limb's own part, and the torso
/// when `skip_torso`, excepted): at 9 points along `a`–`b` (only the 5 of the far half when
/// `skip_torso`: the near end is the attachment), every other part's signed distance exceeds
/// `r + clearance`.
struct Clearance {
    part: usize,
    a: V3,
    b: V3,
    r: f64,
    skip_torso: bool,
}

/// Gap kept between a limb and other parts for grid spacing `cell`: larger than every blend
/// radius and than 1.6 cells, so the polygonised surfaces stay apart too.
fn clearance(cell: f64) -> f64 {
    (1.6 * cell).max(0.06)
}

impl Clearance {
    /// The segment `a`–`b` of radius `r` of part `part`.
    fn segment(part: usize, a: V3, b: V3, r: f64, skip_torso: bool) -> Self {
        Self {
            part,
            a,
            b,
            r,
            skip_torso,
        }
    }

    fn holds(&self, model: &Model, clearance: f64) -> bool {
        let first = if self.skip_torso { 4 } else { 0 };
        (first..9).all(|k| {
            let p = add(
                self.a,
                scale(super::sdf::sub(self.b, self.a), k as f64 / 8.0),
            );
            model.parts.iter().enumerate().all(|(i, part)| {
                i == self.part
                    || (self.skip_torso && i == 0)
                    || part
                        .as_ref()
                        .is_none_or(|part| part.eval(p) > self.r + clearance)
            })
        })
    }
}

fn part(primitives: Vec<Primitive>, blend: f64) -> Option<Part> {
    Some(Part { primitives, blend })
}

fn capsule(a: V3, b: V3, ra: f64, rb: f64) -> Primitive {
    Primitive::Capsule { a, b, ra, rb }
}

/// A two-segment limb from `root`: half of `len` along the unit direction `upper` to the joint,
/// then half along `lower` to the end, with radius `radii` at the root, the joint and the end
/// (the legs and arms of every family). Returns the joint, the end and the limb's part.
fn limb(root: V3, upper: V3, lower: V3, len: f64, radii: [f64; 3]) -> (V3, V3, Option<Part>) {
    let joint = add(root, scale(upper, 0.5 * len));
    let end = add(joint, scale(lower, 0.5 * len));
    let limb = part(
        vec![
            capsule(root, joint, radii[0], radii[1]),
            capsule(joint, end, radii[1], radii[2]),
        ],
        0.03,
    );
    (joint, end, limb)
}

/// Builds shape number `index` of `family` from `params`; returns the model and the grid cell.
pub(crate) fn build(family: Family, index: usize, params: &mut Params) -> (Model, f64) {
    // Resolution: cell size drawn per shape (vertex counts differ by 2×+ across a family),
    // spread over the range (shape i at level i mod 3, see `Params::spread`) so every family of
    // 3+ shapes spans fine and coarse grids; then capped at the thinnest primitive radius.
    let (lo, hi) = family.cell_range();
    let drawn = params.spread("cell_drawn", lo, hi, index % 3);
    let clearance = clearance(drawn);
    // Poses whose limbs run into other parts are redrawn (the stream continues, so this is
    // deterministic); only the accepted draw is kept in the record.
    let mark = params.drawn.len();
    let mut rejected = 0;
    let model = loop {
        let (model, checks) = match family {
            Family::Quadrupeds => quadruped(index, params, clearance),
            Family::Humanoids => humanoid(index, params, clearance),
            Family::Goblets => (goblet(index, params), Vec::new()),
            Family::Chairs => (chair(index, params), Vec::new()),
        };
        if rejected == MAX_REDRAWS || checks.iter().all(|c| c.holds(&model, clearance)) {
            break model;
        }
        rejected += 1;
        params.drawn.truncate(mark);
    };
    params.record("rejected_poses", rejected as f64);
    let cap = super::sdf::round_to(model.thickness(), 1e4);
    let cell = drawn.min(cap);
    params.record("cell", cell);
    (model, cell)
}

/// Spread level of limb lengths for shape `index` (decorrelated from the grid level
/// `index % 3`).
fn limb_level(index: usize) -> usize {
    (index + index / 3) % 3
}

/// Spread level of body sizes for shape `index`.
fn torso_level(index: usize) -> usize {
    (2 * index + 1) % 3
}

/// Quadruped: torso, head (with neck), four two-segment legs, tail.
fn quadruped(index: usize, p: &mut Params, clear: f64) -> (Model, Vec<Clearance>) {
    let torso_len = p.spread("torso_length", 0.65, 1.5, torso_level(index));
    let rt = p.uniform("torso_radius", 0.17, 0.26);
    let leg_len = p.spread("leg_length", 0.32, 0.96, limb_level(index));
    let rl = p.uniform("leg_radius", 0.075, 0.1);
    let hip_y = leg_len + rl;
    let yc = hip_y + 0.5 * rt;
    let torso = Primitive::Ellipsoid {
        c: [0.0, yc, 0.0],
        r: [0.5 * torso_len + 0.3 * rt, rt, 0.95 * rt],
        rot: IDENTITY,
    };
    let mut legs = Vec::new();
    let mut checks = Vec::new();
    for (k, (name, front, side)) in [
        ("leg_front_left", true, 1.0),
        ("leg_front_right", true, -1.0),
        ("leg_back_left", false, 1.0),
        ("leg_back_right", false, -1.0),
    ]
    .into_iter()
    .enumerate()
    {
        let swing = p.uniform(&format!("{name}_swing"), -0.5, 0.5);
        let knee = p.uniform(&format!("{name}_knee"), 0.0, 0.7);
        let x = if front { 0.375 } else { -0.375 } * torso_len;
        let hip = [
            x,
            yc - 0.5 * rt,
            side * (0.55 * rt).max(1.15 * rl + 0.5 * clear + 0.01),
        ];
        let upper = mat_vec(&rotation(2, swing), DOWN);
        let bend = if front { -knee } else { knee };
        let lower = mat_vec(&rotation(2, swing + bend), DOWN);
        let (knee_p, foot, leg) = limb(hip, upper, lower, leg_len, [1.15 * rl, rl, 0.9 * rl]);
        checks.push(Clearance::segment(2 + k, knee_p, foot, rl, true));
        checks.push(Clearance::segment(2 + k, hip, knee_p, 1.15 * rl, true));
        legs.push(leg);
    }
    let neck_angle = p.uniform("neck_angle", 0.3, 1.1);
    let neck_len = p.uniform("neck_length", 0.2, 0.5);
    let hr = p.uniform("head_radius", 0.12, 0.2);
    let neck_a = [0.4 * torso_len, yc + 0.3 * rt, 0.0];
    let neck_dir = mat_vec(&rotation(2, neck_angle), [1.0, 0.0, 0.0]);
    let head_c = add(neck_a, scale(neck_dir, neck_len + 0.5 * hr));
    let head = part(
        vec![
            capsule(neck_a, head_c, (0.45 * rt).max(0.08), 0.6 * hr),
            Primitive::Ellipsoid {
                c: add(head_c, [0.3 * hr, 0.0, 0.0]),
                r: [1.4 * hr, hr, 0.9 * hr],
                rot: IDENTITY,
            },
        ],
        0.05,
    );
    let tail_angle = p.uniform("tail_angle", -0.9, 0.9);
    let tail_len = p.uniform("tail_length", 0.2, 0.6);
    let tail_a = [-0.5 * torso_len, yc + 0.3 * rt, 0.0];
    let tail_dir = mat_vec(&rotation(2, -tail_angle), [-1.0, 0.0, 0.0]);
    let tail = part(
        vec![capsule(
            tail_a,
            add(tail_a, scale(tail_dir, tail_len + 0.2 * torso_len)),
            0.09,
            0.075,
        )],
        0.0,
    );
    let mut parts = vec![part(vec![torso], 0.0), head];
    parts.extend(legs);
    parts.push(tail);
    (Model { parts, blend: 0.05 }, checks)
}

/// Humanoid: torso, head (with neck), two two-segment arms, two two-segment legs.
fn humanoid(index: usize, p: &mut Params, clear: f64) -> (Model, Vec<Clearance>) {
    let leg_len = p.spread("leg_length", 0.5, 1.15, limb_level(index));
    let lr = p.uniform("leg_radius", 0.08, 0.11);
    let torso_len = p.uniform("torso_length", 0.45, 0.8);
    let tw = p.uniform("torso_half_width", 0.16, 0.28);
    let td = p.uniform("torso_half_depth", 0.11, 0.15);
    let arm_len = p.spread("arm_length", 0.42, 1.0, torso_level(index));
    let ar = p.uniform("arm_radius", 0.075, 0.095);
    let hr = p.uniform("head_radius", 0.1, 0.16);
    let yc = leg_len + 0.5 * torso_len;
    let torso = Primitive::Ellipsoid {
        c: [0.0, yc, 0.0],
        r: [tw, 0.5 * torso_len + 0.05, td],
        rot: IDENTITY,
    };
    let top = yc + 0.5 * torso_len;
    let head_c = [0.0, top + hr + 0.04, 0.0];
    let head = part(
        vec![
            capsule([0.0, top - 0.05, 0.0], head_c, 0.075, 0.075),
            Primitive::Ellipsoid {
                c: head_c,
                r: [hr, 1.15 * hr, hr],
                rot: IDENTITY,
            },
        ],
        0.04,
    );
    let mut checks = Vec::new();
    let arms = humanoid_arms(p, tw, top, arm_len, ar, &mut checks);
    let legs = humanoid_legs(p, tw, lr, leg_len, clear, &mut checks);
    let mut parts = vec![part(vec![torso], 0.0), head];
    parts.extend(arms);
    parts.extend(legs);
    (Model { parts, blend: 0.05 }, checks)
}

/// The humanoid's two arms (parts 2 and 3), their clearance checks appended to `checks`; apart
/// from [`humanoid`] to keep it short. Called between the body's and the legs' parameters,
/// since the order of the draws fixes each shape.
fn humanoid_arms(
    p: &mut Params,
    tw: f64,
    top: f64,
    arm_len: f64,
    ar: f64,
    checks: &mut Vec<Clearance>,
) -> Vec<Option<Part>> {
    let mut arms = Vec::new();
    for (k, (name, side)) in [("arm_left", 1.0), ("arm_right", -1.0)]
        .into_iter()
        .enumerate()
    {
        let abduct = p.uniform(&format!("{name}_abduction"), 0.35, 1.6);
        let swing = p.uniform(&format!("{name}_swing"), -0.6, 0.6);
        let elbow = p.uniform(&format!("{name}_elbow"), 0.0, 1.2);
        let shoulder = [side * 0.85 * tw, top - 0.08, 0.0];
        let base = rotation(2, side * abduct);
        let upper = mat_vec(&mat_mul(&base, &rotation(0, -swing)), DOWN);
        let lower = mat_vec(&mat_mul(&base, &rotation(0, -swing - elbow)), DOWN);
        let (elbow_p, hand, arm) = limb(shoulder, upper, lower, arm_len, [1.1 * ar, ar, 0.95 * ar]);
        checks.push(Clearance::segment(2 + k, elbow_p, hand, ar, false));
        checks.push(Clearance::segment(2 + k, shoulder, elbow_p, 1.1 * ar, true));
        arms.push(arm);
    }
    arms
}

/// The humanoid's two legs (parts 4 and 5), their clearance checks appended to `checks`;
/// called after [`humanoid_arms`] so that the parameters are drawn in the same order.
fn humanoid_legs(
    p: &mut Params,
    tw: f64,
    lr: f64,
    leg_len: f64,
    clear: f64,
    checks: &mut Vec<Clearance>,
) -> Vec<Option<Part>> {
    let mut legs = Vec::new();
    for (k, (name, side)) in [("leg_left", 1.0), ("leg_right", -1.0)]
        .into_iter()
        .enumerate()
    {
        let swing = p.uniform(&format!("{name}_swing"), -0.6, 0.6);
        let spread = p.uniform(&format!("{name}_spread"), 0.05, 0.3);
        let knee = p.uniform(&format!("{name}_knee"), 0.0, 0.8);
        let hip = [
            side * (0.55 * tw).max(1.1 * lr + 0.5 * clear + 0.01),
            leg_len + 0.05,
            0.0,
        ];
        let base = rotation(2, side * spread);
        let upper = mat_vec(&mat_mul(&base, &rotation(0, -swing)), DOWN);
        let lower = mat_vec(&mat_mul(&base, &rotation(0, -swing + knee)), DOWN);
        let (knee_p, foot, leg) = limb(hip, upper, lower, leg_len, [1.1 * lr, lr, 0.9 * lr]);
        checks.push(Clearance::segment(4 + k, knee_p, foot, lr, true));
        legs.push(leg);
    }
    legs
}

/// Goblet or cup: bowl (open spherical shell), stem, foot (base), handle on odd-numbered
/// shapes.
fn goblet(index: usize, p: &mut Params) -> Model {
    let base_r = p.uniform("base_radius", 0.2, 0.4);
    let base_h = p.uniform("base_half_height", 0.06, 0.08);
    let stem_len = p.spread("stem_length", 0.06, 0.7, limb_level(index));
    let stem_r = p.uniform("stem_radius", 0.065, 0.095);
    let r = p.spread("bowl_radius", 0.25, 0.47, torso_level(index));
    let rim = p.uniform("rim_height", 0.15, 0.6) * r;
    let t = p.uniform("wall_half_thickness", 0.06, 0.075);
    let has_handle = index % 2 == 1;
    p.record("handle", if has_handle { 1.0 } else { 0.0 });
    let base = Primitive::RoundCylinder {
        c: [0.0, base_h, 0.0],
        r: base_r,
        h: base_h,
        round: 0.8 * base_h,
    };
    let bottom = 2.0 * base_h + stem_len;
    let cy = bottom + r + t;
    let stem = capsule([0.0, base_h, 0.0], [0.0, bottom + t, 0.0], stem_r, stem_r);
    let bowl = Primitive::Bowl {
        c: [0.0, cy, 0.0],
        r,
        h: rim,
        t,
        sy: 1.0,
    };
    let handle = if has_handle {
        let big = p.uniform("handle_radius", 0.45, 0.65) * r;
        let small = p.uniform("handle_tube_radius", 0.06, 0.07);
        // Centre on the wall's mid-surface, below the rim by the ring radius and a margin.
        let hy = rim - big - 0.03;
        let hx = (r * r - hy * hy).sqrt();
        part(
            vec![Primitive::CutTorus {
                c: [hx + 0.25 * big, cy + hy, 0.0],
                big,
                small,
                cut_c: [0.0, cy, 0.0],
                cut_r: r,
            }],
            0.0,
        )
    } else {
        None
    };
    Model {
        parts: vec![
            part(vec![bowl], 0.0),
            part(vec![stem], 0.0),
            part(vec![base], 0.0),
            handle,
        ],
        blend: 0.04,
    }
}

/// Chair: seat, four legs, back (absent on shapes 1, 4, 7…: stools), armrests (on some
/// shapes with a back).
fn chair(index: usize, p: &mut Params) -> Model {
    let w = p.uniform("seat_half_width", 0.2, 0.36);
    let dp = p.uniform("seat_half_depth", 0.2, 0.32);
    let st = p.uniform("seat_half_thickness", 0.05, 0.075);
    let leg_len = p.spread("leg_length", 0.3, 0.85, limb_level(index));
    let lr = p.uniform("leg_radius", 0.05, 0.065);
    let splay = p.uniform("leg_splay", 0.0, 0.2);
    let has_back = index % 3 != 1;
    let has_arms = has_back && index.is_multiple_of(2);
    p.record("back", if has_back { 1.0 } else { 0.0 });
    p.record("armrests", if has_arms { 1.0 } else { 0.0 });
    let seat_y = leg_len + st;
    let seat = Primitive::RoundBox {
        c: [0.0, seat_y, 0.0],
        half: [w, st, dp],
        round: 0.7 * st,
        rot: IDENTITY,
    };
    let mut legs = Vec::new();
    for (sx, sz) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
        // The leg starts at the seat's underside so its rounded end stays inside the seat.
        let top = [sx * (w - lr - 0.02), seat_y - st, sz * (dp - lr - 0.02)];
        let dir = [sx * splay, -1.0, sz * splay];
        let k = leg_len / (1.0 + 2.0 * splay * splay).sqrt();
        let foot = add(top, scale(dir, k));
        legs.push(part(vec![capsule(top, foot, lr, lr)], 0.0));
    }
    let (mut back, mut arm_l, mut arm_r) = (None, None, None);
    if has_back {
        let bh = p.spread("back_height", 0.25, 0.75, torso_level(index));
        let tilt = p.uniform("back_tilt", 0.0, 0.35);
        let bt = p.uniform("back_half_thickness", 0.045, 0.06);
        let rot = rotation(0, -tilt);
        let up = mat_vec(&rot, [0.0, 1.0, 0.0]);
        let foot = [0.0, seat_y, -(dp - bt)];
        back = part(
            vec![Primitive::RoundBox {
                c: add(foot, scale(up, 0.5 * bh)),
                half: [0.95 * w, 0.5 * bh, bt],
                round: 0.8 * bt,
                rot,
            }],
            0.0,
        );
        if has_arms {
            let ah = p.uniform("armrest_height", 0.15, 0.3).min(0.8 * bh);
            let ar = 0.05;
            let make = |sx: f64| {
                let x = sx * (w - 0.04);
                let front = [x, seat_y + ah, dp - 0.08];
                // Where the back's mid-plane is at this height.
                let back_z = foot[2] + up[2] / up[1] * ah;
                part(
                    vec![
                        capsule([x, seat_y, dp - 0.08], front, ar, ar),
                        capsule(front, [x, seat_y + ah, back_z], ar, ar),
                    ],
                    0.02,
                )
            };
            arm_l = make(1.0);
            arm_r = make(-1.0);
        }
    }
    let mut parts = vec![part(vec![seat], 0.0)];
    parts.extend(legs);
    parts.push(back);
    parts.push(arm_l);
    parts.push(arm_r);
    Model { parts, blend: 0.04 }
}
