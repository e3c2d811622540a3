//! The PUMA 560 of the book's case study (book ch. 6), in its two models:
//!
//! * `puma560`: the modified-DH model of Table 6.1, built as Appendix B `Forward` builds it:
//!   `B→0` Type 1 (`Harden`, = armcal `dh`) fixed with θ = parameter 4; `0→1`, `2→3` … `4→5`
//!   Type 1 and `1→2` Type 2 (`Modden`, = armcal `hayati`) with the joint variable added to
//!   θ (`th = theta(jt-1) + param(jt,4)`); `5→6` Type 3 (`Trans`, eq. 6.4, = armcal
//!   `book_type3`) with the joint added to θz;
//! * `puma560-zrp`: the zero-reference model of Table 6.2 with T₀ of eq. 6.11,
//!   `T = D₁ ⋯ D₆ T₀` (eq. 2.75).
//!
//! The book works in inches and degrees; armcal stores mm (× 25.4) and rad. The readers
//! [`book_dh_spec`] and [`book_zrp_spec`] build the same models from the book's tables in
//! CSV form (Tables 6.1/6.5/6.6/6.11 and 6.2/6.7/6.8/6.12, Table 2.1), for the book checks.
//!
//! **T₀ of the identified zero-reference models.** Tables 6.7, 6.8 and 6.12 print no T₀:
//! §6.1.2 assigns T₀ (eq. 6.11) once and identifies six joint offsets instead ("we will
//! choose to assign T₀ and let the additional six unknowns be the joint offsets"), so the
//! identified models use the T₀ of eq. 6.11 unchanged. With it, FK(Table 6.5) and
//! FK(Table 6.7) agree to the book's ≈ 0.015 in without any fitted base or tool transform.

use super::{capsule, frame_link, joint_link, Capsule, Robot};
use crate::model::{
    forward_kinematics, Convention, Data, LinkGeometry, LinkSpec, Model, ModelSpec, Pose,
};
use crate::Error;
use nalgebra::{Matrix3, Vector3};

/// Millimetres per inch.
pub const MM_PER_IN: f64 = 25.4;

/// Joint limits (deg) of the PUMA 560 as commonly published for the Unimation arm.
const LIMITS_DEG: [(f64, f64); 6] = [
    (-160.0, 160.0),
    (-225.0, 45.0),
    (-45.0, 225.0),
    (-110.0, 170.0),
    (-100.0, 100.0),
    (-266.0, 266.0),
];

/// Table 6.1: transform type (1 `Harden`, 2 `Modden`, 3 `Trans`) and parameters 1–6 (in,
/// deg; see [`book_link`]). Row `B→0`, then `0→1` … `5→6` ("2 213" read as 2.213, as in the
/// Appendix B `Par` listing).
const TABLE_6_1: [(u8, [f64; 6]); 7] = [
    (1, [32.878, -15.591, -90.0, 0.0, 0.0, 0.0]),
    (1, [14.681, 0.0, -90.0, 0.0, 0.0, 0.0]),
    (2, [17.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
    (1, [5.870, -0.800, 90.0, 0.0, 0.0, 0.0]),
    (1, [17.050, 0.0, -90.0, 0.0, 0.0, 0.0]),
    (1, [0.0, 0.0, 90.0, 0.0, 0.0, 0.0]),
    (3, [0.0, 0.0, 2.213, 0.0, 0.0, 90.0]),
];

/// Table 6.2: axis direction u, point p (in) and joint offset (deg) of joints 1–6 in the
/// zero position.
const TABLE_6_2: [([f64; 3], [f64; 3], f64); 6] = [
    ([0.0, 1.0, 0.0], [-15.00, 14.70, 33.60], 0.0),
    ([0.0, 0.0, -1.0], [-15.00, 14.70, 27.73], 0.0),
    ([0.0, 0.0, -1.0], [2.00, 14.70, 27.73], 0.0),
    ([0.0, 1.0, 0.0], [1.20, 31.75, 27.73], 0.0),
    ([0.0, 0.0, -1.0], [1.20, 31.75, 27.73], 0.0),
    ([0.0, 1.0, 0.0], [1.20, 31.75, 27.73], 0.0),
];

/// Eq. 6.11: T₀, the tool pose in the zero position (rotation rows, translation in in).
const T0_6_11: [[f64; 4]; 3] = [
    [0.0, -1.0, 0.0, 1.2],
    [0.0, 0.0, 1.0, 33.96],
    [-1.0, 0.0, 0.0, 27.73],
];

const SOURCE_LIMITS: &str = "Joint limits are the commonly published Unimation PUMA 560 \
    limits (deg): q1 ±160, q2 [−225, 45], q3 [−45, 225], q4 [−110, 170], q5 ±100, q6 ±266. \
    They fit the book's zero and joint directions (at q = 0 the upper arm is horizontal and \
    the forearm points up, u2 = u3 = −z): the q2 range is centred on the upper arm pointing \
    up (q2 = −90°) and the q3 range on the straight elbow (q3 = +90°), each ±135°. Capsules \
    are armcal's choice (the book gives no collision geometry): lengths from Table 6.1, \
    radii estimated.";

/// The book's modified-DH PUMA 560 (Table 6.1, Appendix B `Forward`).
pub(super) fn puma560() -> Robot {
    let rows: Vec<BookRow> = TABLE_6_1
        .iter()
        .map(|&(kind, p)| BookRow { kind, p })
        .collect();
    let spec = dh_spec("puma560", &rows).expect("Table 6.1 is a valid model");
    Robot {
        name: "puma560".into(),
        summary: "PUMA 560 of the book's case study, modified DH (Table 6.1), inches → mm".into(),
        source: format!(
            "Mooring, Roth, Driels (1991) Table 6.1 and Appendix B `Forward`: B→0 DH fixed, \
             0→1 and 2→3…4→5 DH, 1→2 Hayati, 5→6 book Type 3 with q6 on θz; the world is the \
             CMM frame B. {SOURCE_LIMITS}"
        ),
        spec,
        capsules: dh_capsules(),
        collision: super::HAND_MADE.into(),
    }
}

/// The book's zero-reference PUMA 560 (Table 6.2, T₀ of eq. 6.11).
pub(super) fn puma560_zrp() -> Robot {
    let rows: Vec<ZrpRow> = TABLE_6_2
        .iter()
        .map(|&(u, p, offset_deg)| ZrpRow { u, p, offset_deg })
        .collect();
    let spec = zrp_spec("puma560-zrp", &rows, &T0_6_11, MM_PER_IN).expect("Table 6.2 is valid");
    let dh = puma560();
    let capsules = transfer_capsules(&dh.spec, &spec, &dh.capsules);
    Robot {
        name: "puma560-zrp".into(),
        summary: "PUMA 560 of the book's case study, zero-reference model (Table 6.2, eq. 6.11)"
            .into(),
        source: format!(
            "Mooring, Roth, Driels (1991) Table 6.2 (u, p) and eq. 6.11 (T₀), T = D1…D6 T0 \
             (eq. 2.75), offsets 0. The nominal ZRP and DH tables place the robot 0.93 in \
             apart (the axes differ by (0.591, 0.019, 0.722) in, the tool lengths by \
             0.003 in); rotations agree at every q. {SOURCE_LIMITS} The capsules are those of \
             `puma560` moved by the same offset."
        ),
        spec,
        capsules,
        collision: super::HAND_MADE.into(),
    }
}

/// Capsules of the DH model, in the frame at the end of each named link (mm). At q = 0 the
/// world y axis is axis 1 (up), the upper arm lies along +x and the forearm points up.
fn dh_capsules() -> Vec<Capsule> {
    let i = MM_PER_IN;
    let upper_arm = 17.0 * i; // 1→2 l
    let shoulder_offset = 5.870 * i; // 2→3 d
    let elbow_offset = 0.800 * i; // −(2→3 l)
    let forearm = 17.050 * i; // 3→4 d
    let flange = 2.213 * i; // 5→6 dz
    vec![
        // pedestal along axis 1 (z0): from about the floor (shoulder ≈ 26 in above it) to
        // below the shoulder housing; frame 1 is 14.681 in above frame 0
        capsule("base", [0.0, 0.0, -290.0], [0.0, 0.0, 250.0], 100.0),
        // shoulder housing, along axis 2 (z1)
        capsule("j1", [0.0, 0.0, -160.0], [0.0, 0.0, 60.0], 110.0),
        // upper arm from axis 2 to axis 3 along x2
        capsule("j2", [-upper_arm, 0.0, 0.0], [0.0, 0.0, 0.0], 90.0),
        // elbow: axis 3 runs along y3 at x3 = 0.8 in; from the upper-arm plane to the forearm
        capsule(
            "j3",
            [elbow_offset, -shoulder_offset, 0.0],
            [0.0, 0.0, 0.0],
            80.0,
        ),
        // forearm along z3 to the wrist centre
        capsule("j3", [0.0, 0.0, -50.0], [0.0, 0.0, forearm - 70.0], 65.0),
        // wrist housing along axis 5 (z4)
        capsule("j4", [0.0, 0.0, -60.0], [0.0, 0.0, 60.0], 50.0),
        // flange along axis 6 (z5)
        capsule("j5", [0.0, 0.0, 0.0], [0.0, 0.0, flange], 40.0),
    ]
}

/// Capsules of one model carried to another model of the same robot whose world frame is
/// translated (not rotated) from the first: a capsule point fixed to frame `k` of `from` is
/// taken to the world at q = 0, shifted by the difference of the two tool origins at q = 0,
/// and expressed in frame `k` of `to` at q = 0. (For the PUMA tables the joint axes differ
/// by 0.003 in more along y than the tool origins, which is immaterial for capsules.)
fn transfer_capsules(from: &ModelSpec, to: &ModelSpec, capsules: &[Capsule]) -> Vec<Capsule> {
    let frames = |spec: &ModelSpec| {
        let model = Model::from_spec(spec).expect("library models are valid");
        let mut data = Data::new(&model);
        forward_kinematics(&model, &mut data, &model.nominal(), &vec![0.0; model.dof()]);
        (model, data.frames)
    };
    let (from_model, from_frames) = frames(from);
    let (to_model, to_frames) = frames(to);
    let shift = to_frames.last().expect("tool").trans - from_frames.last().expect("tool").trans;
    capsules
        .iter()
        .map(|c| {
            let f = &from_frames[from_model.link_index(&c.frame).expect("capsule frame")];
            let t = to_frames[to_model.link_index(&c.frame).expect("capsule frame")].inverse();
            let map = |x: [f64; 3]| -> [f64; 3] {
                (t.transform_point(&(f.transform_point(&Vector3::from(x)) + shift))).into()
            };
            Capsule {
                frame: c.frame.clone(),
                a: map(c.a),
                b: map(c.b),
                radius: c.radius,
            }
        })
        .collect()
}

/// One row of a Table 6.1-format table: transform type and parameters 1–6 (in, deg).
struct BookRow {
    kind: u8,
    p: [f64; 6],
}

/// One row of a Table 6.2-format table: u, p (table length unit) and offset (deg).
struct ZrpRow {
    u: [f64; 3],
    p: [f64; 3],
    offset_deg: f64,
}

/// Joint `i` (1-based) limits in degrees.
fn limits(i: usize) -> (f64, f64) {
    LIMITS_DEG[i - 1]
}

/// One transform of a Table 6.1-format table (book §6.1.1 and Appendix B), inches and
/// degrees → mm and rad:
/// * Type 1 (`Harden`, eq. 6.1): p1 = d (r), p2 = l, p3 = α, p4 = δθ →
///   `Rz(δθ+q) Tz(d) Tx(l) Rx(α)` (armcal `dh`);
/// * Type 2 (`Modden`, §6.1.1): p1 = l, p2 = α, p3 = β, p4 = δθ →
///   `Rz(δθ+q) Tx(l) Rx(α) Ry(β)` (armcal `hayati`);
/// * Type 3 (`Trans`, eqs. 6.4–6.8): p1..p3 = dx, dy, dz, p4..p6 = θx, θy, θz →
///   `Rz(θz+q) Ry(θy) Rx(θx) T(dx, dy, dz)` (armcal `book_type3`).
fn book_link(row: &BookRow) -> Result<LinkGeometry, String> {
    let [p1, p2, p3, p4, p5, p6] = row.p;
    let (l, d) = (MM_PER_IN, f64::to_radians);
    Ok(match row.kind {
        1 => LinkGeometry::dh(d(p4), l * p1, l * p2, d(p3)),
        2 => LinkGeometry::hayati(d(p4), l * p1, d(p2), d(p3)),
        3 => LinkGeometry::new(
            Convention::BookType3,
            vec![l * p1, l * p2, l * p3, d(p4), d(p5), d(p6)],
        ),
        k => return Err(format!("unknown transform type {k} (the book has 1, 2, 3)")),
    })
}

/// Row 1 is the fixed `base` (`B→0`, θ = parameter 4 and no joint); row `i + 1` is link
/// `j<i>` with revolute joint `q<i>` added to θ (θz for Type 3); then an identity `tool`.
fn dh_spec(name: &str, rows: &[BookRow]) -> Result<ModelSpec, Error> {
    let err = |r: usize, m: String| Error::File {
        file: name.into(),
        message: format!("row {r}: {m}"),
    };
    if rows.len() != LIMITS_DEG.len() + 1 {
        return Err(Error::File {
            file: name.into(),
            message: format!(
                "needs the B→0 row and 6 joint rows, got {} rows",
                rows.len()
            ),
        });
    }
    let mut links = Vec::with_capacity(rows.len() + 1);
    for (i, row) in rows.iter().enumerate() {
        let geometry = book_link(row).map_err(|m| err(i + 1, m))?;
        links.push(if i == 0 {
            LinkSpec {
                name: "base".into(),
                geometry,
                joint: None,
            }
        } else {
            joint_link(i, geometry, limits(i))
        });
    }
    links.push(frame_link("tool", [0.0; 3], [0.0; 3]));
    Ok(ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: name.into(),
        instrument: None,
        links,
        targets: vec![],
    })
}

/// Links `base` (identity), `j<i>` = zero-reference joint `i` with its offset, `tool` = T₀.
/// The axis components are taken as printed except the one the book makes dependent
/// (eq. 6.10, Tables 2.2 and 6.3: the component nearest ±1, `u_y` for joints 1, 4, 6 and
/// `u_z` for 2, 3, 5), which is recomputed as `±√(1 − u_a² − u_b²)` from the other two.
fn zrp_spec(name: &str, rows: &[ZrpRow], t0: &[[f64; 4]; 3], mm: f64) -> Result<ModelSpec, Error> {
    let err = |m: String| Error::File {
        file: name.into(),
        message: m,
    };
    if rows.len() != LIMITS_DEG.len() {
        return Err(err(format!("needs 6 joint rows, got {}", rows.len())));
    }
    let rot = Matrix3::from_fn(|r, c| t0[r][c]);
    if (rot.transpose() * rot - Matrix3::identity()).amax() > 1e-6 {
        return Err(err(format!("T0 rotation {rot} is not orthonormal")));
    }
    let pose = Pose {
        rot,
        trans: Vector3::new(t0[0][3], t0[1][3], t0[2][3]) * mm,
    };
    let (xyz, rpy) = pose.to_xyz_rpy();
    let mut links = vec![frame_link("base", [0.0; 3], [0.0; 3])];
    for (i, row) in rows.iter().enumerate() {
        let u = dependent_axis(row.u).map_err(|m| err(format!("joint {}: {m}", i + 1)))?;
        let geometry = LinkGeometry::zrp(u, row.p.map(|x| x * mm), row.offset_deg.to_radians());
        links.push(joint_link(i + 1, geometry, limits(i + 1)));
    }
    links.push(LinkSpec {
        name: "tool".into(),
        geometry: LinkGeometry::frame6(xyz, rpy),
        joint: None,
    });
    Ok(ModelSpec {
        compliance: None,
        periodic: None,
        payloads: Vec::new(),
        name: name.into(),
        instrument: None,
        links,
        targets: vec![],
    })
}

/// The axis with its largest component recomputed from the other two (book eq. 6.10).
fn dependent_axis(u: [f64; 3]) -> Result<[f64; 3], String> {
    let k = (0..3)
        .max_by(|&a, &b| u[a].abs().total_cmp(&u[b].abs()))
        .expect("three components");
    let rest: f64 = (0..3).filter(|&i| i != k).map(|i| u[i] * u[i]).sum();
    if rest >= 1.0 {
        return Err(format!("axis {u:?} has no unit completion"));
    }
    let mut v = u;
    v[k] = (1.0 - rest).sqrt().copysign(u[k]);
    Ok(v)
}

/// Reads a CSV table with named columns into rows of strings.
fn read_csv(name: &str, text: &str) -> Result<(Vec<String>, Vec<Vec<String>>), Error> {
    let err = |m: String| Error::File {
        file: name.into(),
        message: m,
    };
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| err(e.to_string()))?
        .iter()
        .map(str::to_string)
        .collect();
    let rows = reader
        .records()
        .map(|r| {
            r.map(|r| r.iter().map(|s| s.trim().to_string()).collect())
                .map_err(|e| err(e.to_string()))
        })
        .collect::<Result<_, _>>()?;
    Ok((headers, rows))
}

/// Index of a column, or an error naming the file and the missing column.
fn column(name: &str, headers: &[String], col: &str) -> Result<usize, Error> {
    headers
        .iter()
        .position(|h| h == col)
        .ok_or_else(|| Error::File {
            file: name.into(),
            message: format!("no column `{col}` (columns: {})", headers.join(", ")),
        })
}

/// A number from a cell; an empty cell is 0 (unused parameters of Type 1 and 2 rows).
fn number(name: &str, row: usize, col: &str, cell: &str) -> Result<f64, Error> {
    if cell.is_empty() {
        return Ok(0.0);
    }
    cell.parse().map_err(|_| Error::File {
        file: name.into(),
        message: format!("row {row}, column `{col}`: `{cell}` is not a number"),
    })
}

/// The length unit of a column named `<col>_in` or `<col>_mm`: (column name, mm per unit).
fn length_column(name: &str, headers: &[String], col: &str) -> Result<(String, f64), Error> {
    for (suffix, mm) in [("in", MM_PER_IN), ("mm", 1.0)] {
        let c = format!("{col}_{suffix}");
        if headers.contains(&c) {
            return Ok((c, mm));
        }
    }
    Err(Error::File {
        file: name.into(),
        message: format!("no column `{col}_in` or `{col}_mm`"),
    })
}

/// A modified-DH PUMA from a table in the format of the book's Tables 6.1, 6.5, 6.6 and
/// 6.11 (CSV columns `transform,type,p1,…,p6`; inches and degrees; empty cells are 0). Row 1
/// is `B→0` (the fixed `base` link, θ = p4, no joint); each further row is a joint link
/// `j1…`, with the joint variable added to θ (Type 1, 2) or θz (Type 3) as Appendix B
/// `Forward` does; the model ends with an identity `tool` frame. Parameters (book §6.1.1):
/// Type 1 (`Harden`, eq. 6.1, armcal `dh`) p1–p4 = d, l, α, δθ; Type 2 (`Modden`, §6.1.1,
/// armcal `hayati`) p1–p4 = l, α, β, δθ; Type 3 (`Trans`, eq. 6.4, armcal `book_type3`)
/// p1–p6 = dx, dy, dz, θx, θy, θz. Joint limits are the PUMA 560 limits of the `puma560`
/// robot. `name` names the model and errors.
pub fn book_dh_spec(name: &str, csv: &str) -> Result<ModelSpec, Error> {
    let (headers, cells) = read_csv(name, csv)?;
    let kind_col = column(name, &headers, "type")?;
    let p_cols = (1..=6)
        .map(|k| column(name, &headers, &format!("p{k}")))
        .collect::<Result<Vec<_>, _>>()?;
    let rows = cells
        .iter()
        .enumerate()
        .map(|(r, row)| {
            let kind = row[kind_col].parse::<u8>().map_err(|_| Error::File {
                file: name.into(),
                message: format!("row {}: type `{}` is not 1, 2 or 3", r + 1, row[kind_col]),
            })?;
            let mut p = [0.0; 6];
            for (k, &c) in p_cols.iter().enumerate() {
                p[k] = number(name, r + 1, &headers[c], &row[c])?;
            }
            Ok(BookRow { kind, p })
        })
        .collect::<Result<Vec<_>, Error>>()?;
    dh_spec(name, &rows)
}

/// A zero-reference PUMA from a table in the format of the book's Tables 6.2, 6.7, 6.8,
/// 6.12 (inches) or 2.1 (mm) and its T₀ in the format of eq. 6.11 / 2.76:
/// * `table_csv`: columns `joint,u_x,u_y,u_z,p_x_<u>,p_y_<u>,p_z_<u>[,offset_deg]` with
///   `<u>` = `in` or `mm`; a missing offset column means offsets 0;
/// * `t0_csv`: columns `row,c1,c2,c3,c4_<u>`, rows 1–3 of the homogeneous T₀.
///
/// The model is `T = D₁ ⋯ Dₙ T₀` (eq. 2.75), `Dᵢ = T(pᵢ) Rot(uᵢ, Θᵢ + offsetᵢ) T(−pᵢ)`
/// (eqs. 2.72, 2.78; `VECROT` of Appendix C); `uᵢ`'s dependent component is recomputed as
/// the book's model defines it (eq. 6.10, Table 6.3). The identified tables 6.7, 6.8 and
/// 6.12 use the T₀ of eq. 6.11 (see the module documentation).
pub fn book_zrp_spec(name: &str, table_csv: &str, t0_csv: &str) -> Result<ModelSpec, Error> {
    let (headers, cells) = read_csv(name, table_csv)?;
    let u_cols = ["u_x", "u_y", "u_z"]
        .iter()
        .map(|c| column(name, &headers, c))
        .collect::<Result<Vec<_>, _>>()?;
    let mut p_cols = Vec::new();
    let mut mm = 1.0;
    for c in ["p_x", "p_y", "p_z"] {
        let (col, unit) = length_column(name, &headers, c)?;
        p_cols.push(column(name, &headers, &col)?);
        mm = unit;
    }
    let offset_col = headers.iter().position(|h| h == "offset_deg");
    let rows = cells
        .iter()
        .enumerate()
        .map(|(r, row)| {
            let get = |c: usize| number(name, r + 1, &headers[c], &row[c]);
            Ok(ZrpRow {
                u: [get(u_cols[0])?, get(u_cols[1])?, get(u_cols[2])?],
                p: [get(p_cols[0])?, get(p_cols[1])?, get(p_cols[2])?],
                offset_deg: offset_col.map_or(Ok(0.0), get)?,
            })
        })
        .collect::<Result<Vec<_>, Error>>()?;

    let t0_name = format!("{name} (T0)");
    let (t0_headers, t0_cells) = read_csv(&t0_name, t0_csv)?;
    let (c4, t0_mm) = length_column(&t0_name, &t0_headers, "c4")?;
    let cols = ["c1", "c2", "c3", c4.as_str()]
        .iter()
        .map(|c| column(&t0_name, &t0_headers, c))
        .collect::<Result<Vec<_>, _>>()?;
    if t0_cells.len() < 3 {
        return Err(Error::File {
            file: t0_name,
            message: format!("T0 needs 3 rows, got {}", t0_cells.len()),
        });
    }
    let mut t0 = [[0.0; 4]; 3];
    for (r, row) in t0_cells.iter().take(3).enumerate() {
        for (k, &c) in cols.iter().enumerate() {
            t0[r][k] = number(&t0_name, r + 1, &t0_headers[c], &row[c])?;
        }
        // The translation column is scaled to the table's length unit.
        t0[r][3] *= t0_mm / mm;
    }
    zrp_spec(name, &rows, &t0, mm)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::JointKind;

    #[test]
    fn library_models_build_and_are_revolute() {
        for robot in [puma560(), puma560_zrp()] {
            let model = Model::from_spec(&robot.spec).unwrap();
            assert_eq!(model.dof(), 6);
            assert!(model.joints.iter().all(|j| j.kind == JointKind::Revolute));
            assert_eq!(robot.spec.links.first().unwrap().name, "base");
            assert_eq!(robot.spec.links.last().unwrap().name, "tool");
        }
    }

    #[test]
    fn dependent_component_is_recomputed() {
        let u = dependent_axis([0.407, 0.002, -0.913]).unwrap();
        assert_eq!(u[0], 0.407);
        assert!((u[2] + (1.0f64 - 0.407 * 0.407 - 0.002 * 0.002).sqrt()).abs() < 1e-15);
        assert!(dependent_axis([0.8, 0.75, 0.7]).is_err());
    }

    #[test]
    fn unknown_transform_type_is_an_error() {
        let mut csv =
            "transform,type,p1,p2,p3,p4,p5,p6\nB->0,1,0,0,0,0,,\n0->1,4,0,0,0,0,,\n".to_string();
        for _ in 0..5 {
            csv += "x,1,0,0,0,0,,\n";
        }
        let csv = csv.as_str();
        let e = book_dh_spec("t", csv).unwrap_err().to_string();
        assert!(e.contains("row 2") && e.contains("type 4"), "{e}");
    }

    #[test]
    fn capsules_name_existing_frames() {
        for robot in [puma560(), puma560_zrp()] {
            let model = Model::from_spec(&robot.spec).unwrap();
            for c in &robot.capsules {
                assert!(model.link_index(&c.frame).is_some(), "{}", c.frame);
            }
        }
    }
}
