//! `--up-axis`: assets authored Z-up (Blender, 3ds Max, CAD, the Berkeley garments) lit and
//! framed as they stand. The environment's zenith (+Y of a lat-long map) and the default camera
//! up turn onto the input's up axis; the geometry and every per-vertex output stay in the
//! input's frame, so a_i and M are untouched and only look-ups of the environment change.
//! `translucency`, whose outputs are pictures only, stands the object up instead (its scene
//! rotation, the inverse of [`up_axis_rotation`]) and turns the lights given in its frame.

/// An input's up axis (`--up-axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum UpAxis {
    /// +X up.
    #[value(name = "x")]
    PosX,
    /// +Y up (the default: glTF, OBJ from most tools, the shared data).
    #[value(name = "y")]
    PosY,
    /// +Z up (Blender, 3ds Max, CAD exports, the Berkeley garments).
    #[value(name = "z")]
    PosZ,
    /// −X up.
    #[value(name = "-x")]
    NegX,
    /// −Y up.
    #[value(name = "-y")]
    NegY,
    /// −Z up.
    #[value(name = "-z")]
    NegZ,
}

/// The rotation taking +Y (the environment's zenith, the default camera up) onto `axis`: a
/// quarter or half turn about X or Z, so it maps the lightsphere's octahedral directions onto
/// each other.
pub fn up_axis_rotation(axis: UpAxis) -> glam::DQuat {
    use std::f64::consts::{FRAC_PI_2, PI};
    match axis {
        UpAxis::PosY => glam::DQuat::IDENTITY,
        UpAxis::PosZ => glam::DQuat::from_rotation_x(FRAC_PI_2),
        UpAxis::NegZ => glam::DQuat::from_rotation_x(-FRAC_PI_2),
        UpAxis::PosX => glam::DQuat::from_rotation_z(-FRAC_PI_2),
        UpAxis::NegX => glam::DQuat::from_rotation_z(FRAC_PI_2),
        UpAxis::NegY => glam::DQuat::from_rotation_x(PI),
    }
}

/// The rotation standing an input authored with `axis` up onto +Y (the inverse of
/// [`up_axis_rotation`]) as an exact matrix: every entry is 0 or ±1, so turned positions keep
/// their bits and a mask or picture of the stood-up asset matches that of a Y-up original.
pub fn stand_up_matrix(axis: UpAxis) -> glam::Mat4 {
    let m = glam::DMat3::from_quat(up_axis_rotation(axis).inverse());
    glam::Mat4::from_mat3(glam::Mat3::from_cols_array(
        &m.to_cols_array().map(|v| v.round() as f32),
    ))
}

/// A scene object's `rotation_deg` (XYZ Euler angles) standing an input authored with `axis`
/// up onto +Y: how `translucency` and `view`, whose outputs are pictures only, stand the
/// object up in a Y-up world.
pub fn stand_up_degrees(axis: UpAxis) -> [f32; 3] {
    let (rx, ry, rz) = up_axis_rotation(axis)
        .inverse()
        .to_euler(glam::EulerRot::XYZ);
    [rx, ry, rz].map(|a| a.to_degrees() as f32)
}

/// Turns an automatically framed camera onto `axis`: its up vector becomes `axis` and its
/// viewing direction turns by the same [`up_axis_rotation`], so a Z-up asset is seen as a
/// Y-up one would be.
pub fn turn_camera(camera: &mut cloth_vis::scene::CameraDesc, axis: UpAxis) {
    let up = up_axis_rotation(axis).as_quat();
    camera.up = (up * glam::Vec3::Y).to_array();
    camera.direction = (up * glam::Vec3::from(camera.direction)).to_array();
}
