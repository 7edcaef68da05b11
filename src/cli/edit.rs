//! `campanile edit`: scene editing (thesis §2.5.2).

use std::path::PathBuf;

use anyhow::Result;
use campanile_scan::edit::edit_scene;
use clap::Args;

use super::exit::{EXIT_OK, bad_input};

/// Edit a scene (thesis §2.5.2): merge OBJ groups into named objects, then
/// move, copy and delete objects, writing a new scene.obj and scene.ron.
///
/// SCENE is a scene file (the skeleton `campanile segment` writes, or a full
/// scene file: its materials, camera poses and targets are kept) with its
/// OBJ beside it. EDIT is a RON file:
///
///   SceneEdit(
///       objects: [Object(name: "table", members: ["surface_4", "surface_9"])],
///       operations: [
///           Copy(object: "table", name: "table_2", offset_m: (-2.0, 1.2, 0.0)),
///           Move(object: "table_2", translate_m: (0.0, 0.3, 0.0), rotate_z_deg: 90.0),
///           Delete(object: "surface_3"),
///       ],
///   )
///
/// Move turns the object about the vertical line through its bounding box's
/// centre (counter-clockwise seen from above), then translates it. Copy
/// makes a new object in new OBJ groups that share the original's material.
/// An object or group that does not exist is refused, naming those that do.
/// `campanile render --scene OUT/scene.ron` shows the edited scene.
///
/// Exit status: 0 written, 2 bad input, 1 failure while writing.
///
/// Example:
///   campanile segment scans/room-*.ply --out room-scene/
///   campanile edit room-scene/scene.ron edits.ron --out edited/
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct EditArgs {
    /// The scene file to edit (its OBJ beside it).
    #[arg(value_name = "SCENE.ron")]
    scene: PathBuf,
    /// The edit file (`SceneEdit(...)`).
    #[arg(value_name = "EDIT.ron")]
    edit: PathBuf,
    /// Output directory (scene.obj, scene.ron).
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
}

pub fn run(args: EditArgs) -> Result<u8> {
    let edited = match edit_scene(&args.scene, &args.edit, &args.out) {
        Ok(edited) => edited,
        Err(e) if e.is_bad_input() => return Err(bad_input(e.to_string())),
        Err(e) => return Err(e.into()),
    };
    for o in &edited.objects {
        let triangles: usize = edited
            .meshes
            .iter()
            .filter(|m| o.groups.contains(&m.group))
            .map(|m| m.mesh.triangles.len())
            .sum();
        println!(
            "{}: {} group(s), {triangles} triangles, material {}",
            o.name,
            o.groups.len(),
            o.material
        );
    }
    println!("written to {}", args.out.display());
    Ok(EXIT_OK)
}
