//! The command line: `oit-viewer FILE ... [--method NAME] ...`. Built-in scenes are the Python
//! package's: `python -m oit view --scene NAME` exports one and starts this viewer on the file.

use std::path::PathBuf;

use oit_core::ParamValue;

use crate::state::{Compare, ViewMode};

pub const USAGE: &str = "\
usage: oit-viewer FILE ... [--method NAME] [--param NAME=VALUE ...] [--alpha A]
                  [--background R G B] [--compare off|split|toggle] [--view image|complexity|error]
                  [--size W H] [--adapter NAME] [--hide-panel]
                  [--screenshot PATH [--frames N] [--crop-view]]

FILE           .oitscene (from `python -m oit view --scene NAME --export PATH`), .obj, .ply,
               .stl, .gltf or .glb
--method NAME  the method to start with (default: hybrid); --param sets its parameters
--alpha A      make every mesh transparent at A (default: the files' alphas; 0.4 when nothing in a mesh file is transparent)
--background   linear RGB in [0, 1] (default: 1 1 1)
--size W H     window size in points (default: 1280 800)
--adapter NAME substring of the adapter name (default: OIT_ADAPTER or the best adapter)
--screenshot   render, save the window as PNG after N frames (default 3) and exit;
               --crop-view saves only the rendered view. Needs a display (xvfb-run works)

mouse: drag to orbit, shift-drag or right-drag to pan, scroll to zoom, double-click or R to
reset; Space flips the toggle compare mode; Tab hides the panel

The built-in scenes (hair, smoke, foliage, dragons, glass, stacks) are the Python package's:
`python -m oit view --scene NAME` exports one to a scene file and starts this viewer on it";

#[derive(Clone, Debug)]
pub struct Options {
    pub files: Vec<PathBuf>,
    pub method: String,
    pub params: Vec<(String, ParamValue)>,
    pub alpha: Option<f32>,
    pub background: [f32; 3],
    pub compare: Compare,
    pub view: ViewMode,
    pub size: [f32; 2],
    pub adapter: Option<String>,
    pub hide_panel: bool,
    pub screenshot: Option<PathBuf>,
    pub frames: u32,
    pub crop_view: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            files: vec![],
            method: "hybrid".into(),
            params: vec![],
            alpha: None,
            background: [1.0; 3],
            compare: Compare::Off,
            view: ViewMode::Image,
            size: [1280.0, 800.0],
            adapter: None,
            hide_panel: false,
            screenshot: None,
            frames: 3,
            crop_view: false,
        }
    }
}

/// 'k=v' with v an int, else a float, else the string (as `python -m oit render --param`).
pub fn parse_param(text: &str) -> Result<(String, ParamValue), String> {
    let (k, v) =
        text.split_once('=').filter(|(k, _)| !k.is_empty()).ok_or_else(|| format!("parameters are written name=value, got '{text}'"))?;
    let value = v
        .parse::<i64>()
        .map(ParamValue::Int)
        .or_else(|_| v.parse::<f64>().map(ParamValue::Float))
        .unwrap_or_else(|_| ParamValue::Str(v.to_string()));
    Ok((k.to_string(), value))
}

fn number<T: std::str::FromStr>(flag: &str, text: Option<String>) -> Result<T, String> {
    let text = text.ok_or_else(|| format!("{flag} needs a value"))?;
    text.parse().map_err(|_| format!("{flag}: '{text}' is not a valid number"))
}

fn unit(flag: &str, text: Option<String>) -> Result<f32, String> {
    let v: f32 = number(flag, text)?;
    if !(0.0..=1.0).contains(&v) {
        return Err(format!("{flag}: {v} is outside [0, 1]"));
    }
    Ok(v)
}

/// Parses the arguments after the program name. `Ok(None)` means help was asked for.
pub fn parse(args: impl IntoIterator<Item = String>) -> Result<Option<Options>, String> {
    let mut o = Options::default();
    let mut it = args.into_iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "-h" | "--help" => return Ok(None),
            "--scene" => return Err(scene_moved(it.next().as_deref())),
            "-m" | "--method" => o.method = it.next().ok_or("--method needs a name")?,
            "--param" => o.params.push(parse_param(&it.next().ok_or("--param needs NAME=VALUE")?)?),
            "--alpha" => o.alpha = Some(unit("--alpha", it.next())?),
            "--background" => {
                o.background = [unit("--background", it.next())?, unit("--background", it.next())?, unit("--background", it.next())?]
            }
            "--compare" => {
                o.compare = match it.next().as_deref() {
                    Some("off") => Compare::Off,
                    Some("split") => Compare::Split,
                    Some("toggle") => Compare::Toggle,
                    other => return Err(format!("--compare takes off, split or toggle, got {other:?}")),
                }
            }
            "--view" => {
                o.view = match it.next().as_deref() {
                    Some("image") => ViewMode::Image,
                    Some("complexity") => ViewMode::Complexity,
                    Some("error") => ViewMode::Error,
                    other => return Err(format!("--view takes image, complexity or error, got {other:?}")),
                }
            }
            "--size" => {
                let (w, h): (f32, f32) = (number("--size", it.next())?, number("--size", it.next())?);
                if !(w >= 64.0 && h >= 64.0) {
                    return Err(format!("--size {w} {h}: the window needs at least 64 x 64 points"));
                }
                o.size = [w, h];
            }
            "--adapter" => o.adapter = Some(it.next().ok_or("--adapter needs a name")?),
            "--hide-panel" => o.hide_panel = true,
            "--screenshot" => o.screenshot = Some(PathBuf::from(it.next().ok_or("--screenshot needs a path")?)),
            "--frames" => o.frames = number("--frames", it.next())?,
            "--crop-view" => o.crop_view = true,
            s if s.starts_with('-') && s.len() > 1 => return Err(format!("unknown option '{s}'")),
            _ => o.files.push(PathBuf::from(a)),
        }
    }
    if o.files.is_empty() {
        return Err("name a file to open (for a built-in scene, run `python -m oit view --scene NAME`)".into());
    }
    Ok(Some(o))
}

/// The viewer does not build scenes: the Python package does, and starts the viewer on them.
fn scene_moved(name: Option<&str>) -> String {
    let name = name.unwrap_or("NAME");
    format!(
        "--scene: the built-in scenes are the Python package's; run `python -m oit view --scene {name}`, which \
         exports the scene and starts this viewer on it (or `python -m oit view --scene {name} --export {name}.oitscene`, \
         then `oit-viewer {name}.oitscene`)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Result<Option<Options>, String> {
        parse(s.split_whitespace().map(String::from))
    }

    #[test]
    fn options_and_errors() {
        let o =
            args("a.obj b.ply --method abuffer --param k=4 --param weight=eq10 --alpha 0.3 --compare split --screenshot x.png --frames 2")
                .unwrap()
                .unwrap();
        assert_eq!(o.files.len(), 2);
        assert_eq!(o.params, vec![("k".into(), ParamValue::Int(4)), ("weight".into(), ParamValue::Str("eq10".into()))]);
        assert_eq!((o.alpha, o.compare, o.frames), (Some(0.3), Compare::Split, 2));
        assert!(args("--help").unwrap().is_none());
        assert!(args("--alpha 2 a.obj").unwrap_err().contains("outside [0, 1]"));
        assert!(args("").unwrap_err().contains("python -m oit view --scene NAME"));
        assert!(args("--scene glass --method hybrid").unwrap_err().contains("run `python -m oit view --scene glass`"));
        assert!(args("a.obj --bogus").unwrap_err().contains("unknown option"));
    }
}
