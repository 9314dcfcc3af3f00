//! What the viewer can be told to do, from the keyboard or from a script
//! (`quadray view --script`), and the key bindings.

use std::fmt;

use crate::model::scene::{Preset, MAX_IMAGE_SIZE};

/// One thing the viewer does. Keys and script steps both become actions.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Next texture-filtering mode (none → ray-cones → covariance).
    CycleFilter,
    /// Next quality preset.
    NextPreset,
    /// A given quality preset.
    SetPreset(Preset),
    /// Caustic passes on or off.
    ToggleCaustics,
    /// Volume pass on or off.
    ToggleVolume,
    /// Denoising on or off (Intel Open Image Denoise: the view shows the
    /// denoised image once it has two samples, and denoises again each time
    /// its samples double, and at the last).
    ToggleDenoise,
    /// Save the frame on screen as PNG (the displayed pixels) and EXR (its
    /// linear radiance), under the given name or a numbered one.
    Screenshot(Option<String>),
    /// Save the window's pixels as the X server holds them (NAME.png): what
    /// is on screen, read back through the window system.
    Capture(String),
    /// Back to the scene file's camera.
    ResetCamera,
    /// Move eye and target: forward, right, up, in steps of 5% of their distance.
    Fly(f64, f64, f64),
    /// Orbit the eye around the look-at point (degrees: yaw, pitch).
    Orbit(f64, f64),
    /// Move toward (positive) or away from the look-at point, 10% a step.
    Dolly(f64),
    /// Ask for a new window size (pixels).
    Resize(u32, u32),
    /// Minimise (true) or restore (false) the window.
    Minimize(bool),
    /// Close the window.
    Close,
}

/// A script step: an action, or a wait.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Do this.
    Do(Action),
    /// Wait until this many samples per pixel are on screen (or the target
    /// spp, if lower).
    WaitSamples(u32),
    /// Wait for this many presented frames.
    WaitFrames(u32),
}

/// The key bindings, for the help text and docs/viewer.md.
pub const KEY_HELP: &str = "\
mouse: left drag orbits, right drag turns the view, wheel dollies
W A S D: fly forward, left, back, right    Q E: down, up    (arrow keys: orbit)
F: next filtering mode    P: next preset    1 2 3 4: preview, interactive, final, reference
C: caustics on/off    V: volume on/off    N: denoise on/off    R: reset camera
F12 or O: screenshot (PNG + EXR)    Esc: close";

/// The action of a pressed key (winit's logical key, lower-cased).
pub fn key_action(key: &str) -> Option<Action> {
    Some(match key {
        "f" => Action::CycleFilter,
        "p" => Action::NextPreset,
        "1" => Action::SetPreset(Preset::Preview),
        "2" => Action::SetPreset(Preset::Interactive),
        "3" => Action::SetPreset(Preset::Final),
        "4" => Action::SetPreset(Preset::Reference),
        "c" => Action::ToggleCaustics,
        "v" => Action::ToggleVolume,
        "n" => Action::ToggleDenoise,
        "r" => Action::ResetCamera,
        "o" | "f12" => Action::Screenshot(None),
        "w" => Action::Fly(1.0, 0.0, 0.0),
        "s" => Action::Fly(-1.0, 0.0, 0.0),
        "a" => Action::Fly(0.0, -1.0, 0.0),
        "d" => Action::Fly(0.0, 1.0, 0.0),
        "q" => Action::Fly(0.0, 0.0, -1.0),
        "e" => Action::Fly(0.0, 0.0, 1.0),
        "arrowleft" => Action::Orbit(-5.0, 0.0),
        "arrowright" => Action::Orbit(5.0, 0.0),
        "arrowup" => Action::Orbit(0.0, 5.0),
        "arrowdown" => Action::Orbit(0.0, -5.0),
        "escape" => Action::Close,
        _ => return None,
    })
}

/// A script that cannot be parsed: which step, and why.
#[derive(Debug, PartialEq, Eq)]
pub struct ScriptError {
    /// The step, from 1.
    pub step: usize,
    /// The step's text.
    pub text: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ScriptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "script step {} (`{}`): {}", self.step, self.text, self.message)
    }
}

impl std::error::Error for ScriptError {}

/// The script language, for the help text and docs/viewer.md.
pub const SCRIPT_HELP: &str = "\
steps separated by `;` or new lines:
  wait N            until N samples per pixel are on screen (or all the view's samples)
  frames N          until N more frames are presented
  screenshot [NAME] save NAME.png and NAME.exr in the screenshot folder
  capture NAME      save the window as the X server shows it, NAME.png
  key K             press key K (f, p, 1-4, c, v, n, r, w, a, s, d, q, e, arrowleft, ...)
  orbit YAW PITCH   orbit by these angles (degrees)
  resize WxH        ask for a window of W x H pixels
  minimize | restore
  close";

/// Parses a script (see [`SCRIPT_HELP`]).
pub fn parse_script(text: &str) -> Result<Vec<Step>, ScriptError> {
    text.split([';', '\n'])
        .map(str::trim)
        .filter(|s| !s.is_empty() && !s.starts_with('#'))
        .enumerate()
        .map(|(i, s)| parse_step(s).map_err(|message| ScriptError { step: i + 1, text: s.to_string(), message }))
        .collect()
}

fn parse_step(s: &str) -> Result<Step, String> {
    let words: Vec<&str> = s.split_whitespace().collect();
    let count = |w: &[&str]| -> Result<u32, String> {
        match w {
            [n] => n.parse::<u32>().map_err(|_| format!("`{n}` is not a whole number")),
            _ => Err("expects one number".into()),
        }
    };
    let angle = |w: &str| -> Result<f64, String> {
        w.parse::<f64>().ok().filter(|a| a.is_finite()).ok_or_else(|| format!("`{w}` is not an angle in degrees"))
    };
    Ok(match words[0] {
        "wait" => Step::WaitSamples(count(&words[1..])?),
        "frames" => Step::WaitFrames(count(&words[1..])?),
        "screenshot" => match &words[1..] {
            [] => Step::Do(Action::Screenshot(None)),
            [name] => Step::Do(Action::Screenshot(Some(name.to_string()))),
            _ => return Err("expects at most one name".into()),
        },
        "capture" => match &words[1..] {
            [name] => Step::Do(Action::Capture(name.to_string())),
            _ => return Err("expects one name".into()),
        },
        "key" => match &words[1..] {
            [k] => Step::Do(key_action(&k.to_ascii_lowercase()).ok_or_else(|| format!("no action on key `{k}`"))?),
            _ => return Err("expects one key".into()),
        },
        "orbit" => match &words[1..] {
            [y, p] => Step::Do(Action::Orbit(angle(y)?, angle(p)?)),
            _ => return Err("expects two angles (yaw, pitch)".into()),
        },
        "resize" => {
            let size = words.get(1).and_then(|w| w.split_once('x'));
            let parsed = size.and_then(|(w, h)| Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?)));
            match (parsed, words.len()) {
                (Some((w, h)), 2) if (1..=MAX_IMAGE_SIZE).contains(&i64::from(w)) && (1..=MAX_IMAGE_SIZE).contains(&i64::from(h)) => {
                    Step::Do(Action::Resize(w, h))
                }
                _ => return Err(format!("expects a size such as 320x240 (1 to {MAX_IMAGE_SIZE} each)")),
            }
        }
        "minimize" | "minimise" if words.len() == 1 => Step::Do(Action::Minimize(true)),
        "restore" if words.len() == 1 => Step::Do(Action::Minimize(false)),
        "close" if words.len() == 1 => Step::Do(Action::Close),
        other => return Err(format!("unknown step `{other}`; steps are: wait, frames, screenshot, capture, key, orbit, resize, minimize, restore, close")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scripts_parse() {
        let steps =
            parse_script("wait 4; screenshot a\n# comment\nkey C; resize 80x60; orbit 10 -5; frames 2; close").unwrap();
        assert_eq!(
            steps,
            vec![
                Step::WaitSamples(4),
                Step::Do(Action::Screenshot(Some("a".into()))),
                Step::Do(Action::ToggleCaustics),
                Step::Do(Action::Resize(80, 60)),
                Step::Do(Action::Orbit(10.0, -5.0)),
                Step::WaitFrames(2),
                Step::Do(Action::Close),
            ]
        );
    }

    #[test]
    fn bad_steps_say_which_and_why() {
        let e = parse_script("wait 4; resize 80by60").unwrap_err();
        assert_eq!(e.step, 2);
        assert!(e.to_string().contains("320x240"), "{e}");
        assert!(parse_script("key z").unwrap_err().message.contains("no action"));
        assert!(parse_script("jump").unwrap_err().message.contains("unknown step"));
        assert!(parse_script("wait x").is_err());
        assert!(parse_script("resize 0x10").is_err());
    }

    #[test]
    fn every_bound_key_has_an_action() {
        for k in ["f", "p", "1", "2", "3", "4", "c", "v", "n", "r", "o", "f12", "w", "a", "s", "d", "q", "e", "escape"]
        {
            assert!(key_action(k).is_some(), "{k}");
        }
    }
}
