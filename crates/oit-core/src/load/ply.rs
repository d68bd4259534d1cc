//! PLY (ASCII or binary; vertex colors with alpha: 8-bit ones are sRGB, float ones linear;
//! polygons fanned into triangles) and STL (ASCII or binary; gray, opaque).

use std::path::Path;

use super::{named, srgb_to_linear, NamedMesh, DEFAULT_RGB};

fn stem(path: &Path) -> String {
    path.file_stem().and_then(|s| s.to_str()).unwrap_or("mesh").to_string()
}

pub fn load_ply(path: &Path) -> Result<NamedMesh, String> {
    use ply_rs_bw::ply::Property as P;
    let mut file = std::io::BufReader::new(std::fs::File::open(path).map_err(|e| e.to_string())?);
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut file).map_err(|e| format!("not a readable PLY file ({e})"))?;
    let scalar = |p: Option<&P>| -> Option<f64> {
        Some(match p? {
            P::Char(v) => *v as f64,
            P::UChar(v) => *v as f64,
            P::Short(v) => *v as f64,
            P::UShort(v) => *v as f64,
            P::Int(v) => *v as f64,
            P::UInt(v) => *v as f64,
            P::Float(v) => *v as f64,
            P::Double(v) => *v,
            _ => return None,
        })
    };
    let vertices = ply.payload.get("vertex").ok_or("no 'vertex' element")?;
    let mut positions = Vec::with_capacity(vertices.len());
    let mut colors = Vec::with_capacity(vertices.len());
    for v in vertices {
        let xyz = ["x", "y", "z"].map(|k| scalar(v.get(k)));
        let [Some(x), Some(y), Some(z)] = xyz else { return Err("vertices need x, y and z".into()) };
        positions.push([x as f32, y as f32, z as f32]);
        // 8-bit colors are sRGB (alpha linear); float colors are taken as linear.
        let unit = |k: &str| match v.get(k) {
            Some(P::UChar(c)) => Some(*c as f32 / 255.0),
            p => scalar(p).map(|c| c as f32),
        };
        let rgb = ["red", "green", "blue"].map(unit);
        let c = match rgb {
            [Some(r), Some(g), Some(b)] if matches!(v.get("red"), Some(P::UChar(_))) => [r, g, b].map(srgb_to_linear),
            [Some(r), Some(g), Some(b)] => [r, g, b],
            _ => DEFAULT_RGB,
        };
        colors.push([c[0], c[1], c[2], unit("alpha").unwrap_or(1.0)]);
    }
    let faces = ply.payload.get("face").map(Vec::as_slice).unwrap_or_default();
    let mut indices = Vec::with_capacity(faces.len());
    for f in faces {
        let list: Vec<i64> = match f.get("vertex_indices").or_else(|| f.get("vertex_index")) {
            Some(P::ListInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListChar(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(P::ListUChar(l)) => l.iter().map(|&i| i as i64).collect(),
            _ => return Err("faces need a 'vertex_indices' list".into()),
        };
        if list.iter().any(|&i| i < 0 || i as usize >= positions.len()) {
            return Err(format!("a face refers to a vertex outside [0, {})", positions.len()));
        }
        // A fan triangulates convex polygons.
        for k in 1..list.len().saturating_sub(1) {
            indices.push([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
        }
    }
    let opaque = colors.iter().all(|c| c[3] >= 1.0);
    named(stem(path), positions, indices, colors, opaque)
}

pub fn load_stl(path: &Path) -> Result<NamedMesh, String> {
    let mut file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mesh = stl_io::read_stl(&mut file).map_err(|e| format!("not a readable STL file ({e})"))?;
    let positions = mesh.vertices.iter().map(|v| v.0).collect();
    let indices = mesh.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect();
    let [r, g, b] = DEFAULT_RGB;
    named(stem(path), positions, indices, vec![[r, g, b, 1.0]], true)
}
