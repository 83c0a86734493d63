//! `geofit subdiv`: refinement from the command line, limit positions, and error messages.

use std::path::PathBuf;
use std::process::Command;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/subdiv")
        .join(name)
}

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geofit"))
        .arg("subdiv")
        .args(args)
        .output()
        .expect("runs")
}

#[test]
fn refines_to_an_obj_with_the_expected_counts() {
    let dir = std::env::temp_dir().join(format!("geofit-cli-subdiv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = data("bunny_patch.obj");
    let input_mesh = geofit::io::read_path(&input).unwrap().mesh;
    for (scheme, limit) in [
        ("loop", false),
        ("loop", true),
        ("catmull-clark", true),
        ("doo-sabin", false),
    ] {
        let out = dir.join(format!("{scheme}-{limit}.obj"));
        let mut args = vec![
            input.to_str().unwrap(),
            "--scheme",
            scheme,
            "--levels",
            "2",
            "-o",
            out.to_str().unwrap(),
        ];
        if limit {
            args.push("--limit");
        }
        let o = run(&args);
        assert!(
            o.status.success(),
            "{scheme}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let mesh = geofit::io::read_path(&out).unwrap().mesh;
        let expect_faces = match scheme {
            "loop" => 16 * input_mesh.num_faces(),
            "catmull-clark" => 12 * input_mesh.num_faces(),
            _ => mesh.num_faces(),
        };
        assert_eq!(mesh.num_faces(), expect_faces, "{scheme}");
        assert!(mesh.positions().iter().all(|p| p.is_finite()));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_input_gives_a_message_not_a_crash() {
    let out = std::env::temp_dir().join("geofit-cli-subdiv-never.obj");
    let (bunny, spot) = (data("bunny_patch.obj"), data("spot_quads.obj"));
    for (args, needle) in [
        (vec!["/nonexistent/mesh.obj"], "/nonexistent/mesh.obj"),
        (vec![bunny.to_str().unwrap(), "--levels", "99"], "--levels"),
        // Loop on a quad-dominant mesh names the offending face.
        (vec![spot.to_str().unwrap(), "--scheme", "loop"], "face"),
    ] {
        let o = run(&[args.as_slice(), &["-o", out.to_str().unwrap()]].concat());
        assert!(!o.status.success(), "{args:?}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains(needle),
            "{args:?}"
        );
    }
}
