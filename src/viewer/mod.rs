//! `quadray view`: a window that renders progressively.
//!
//! Each frame adds one sample per pixel to a [`Renderer`], tone-maps the
//! mean on the host (the same code as the PNG output) and presents it
//! through a swapchain; accumulation stops at the view's target (the scene's
//! spp, or `--max-spp`), and starts again whenever the camera or a setting
//! changes. Moving the camera keeps the render pipelines (lavapipe compiles
//! a pipeline at its first dispatch); a new size, preset, filtering mode or
//! pass toggle builds new ones. With denoising on (`N`; the `preview` and
//! `interactive` presets), the view shows the image denoised by Intel Open
//! Image Denoise once it has two samples, keeps it on screen while samples
//! are added, and denoises again when they have doubled and at the last.
//!
//! The keys are in [`actions::KEY_HELP`]; the same actions can be scripted
//! ([`actions::SCRIPT_HELP`]), which is how the tests drive the window under
//! Xvfb.

pub mod actions;
pub mod camera;
mod capture;

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::window::{Window, WindowId};

use crate::jobs::denoise::Denoiser;
use crate::jobs::output::{tone_map, write_outputs, ExrPrecision, OutputKind};
use crate::model::scene::{Preset, Scene};
use crate::passes::{GpuScene, RenderOutput, RenderVariant, Renderer};
use crate::vk::{
    surface_extensions, Commands, Device, Instance, PresentResult, Surface, Swapchain, ValidationCounters, VkError,
};
use actions::{Action, Step};
use camera::CameraController;

/// Errors of the viewer.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// The window system failed.
    #[error("window system: {0}")]
    Window(String),
    /// No display to open a window on.
    #[error(
        "cannot open a window: {0}. On a machine without a display, run the viewer under a virtual X server: \
         `xvfb-run -a quadray view [SCENE] --script 'wait 16; screenshot; close'` (Xvfb: `make setup`)"
    )]
    NoDisplay(String),
    /// Vulkan failed.
    #[error(transparent)]
    Vk(#[from] VkError),
    /// Rendering failed.
    #[error(transparent)]
    Render(#[from] crate::RenderError),
    /// A screenshot could not be written.
    #[error("cannot write the screenshot {}: {source}", .path.display())]
    Screenshot {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// A winit message without the source location it starts with ("os error
/// at /home/.../x11/mod.rs:123: neither WAYLAND_DISPLAY ..." says only
/// "neither WAYLAND_DISPLAY ...").
fn without_source_path(message: &str) -> String {
    match message.find(".rs:").and_then(|i| message[i..].find(": ").map(|j| i + j + 2)) {
        Some(start) => message[start..].trim_end_matches('.').to_string(),
        None => message.trim_end_matches('.').to_string(),
    }
}

/// How to run the viewer.
pub struct ViewerConfig {
    /// The scene (its quality settings as the command line left them).
    pub scene: Scene,
    /// The scene's name, for the title and screenshot names.
    pub name: String,
    /// Turn on the Khronos validation layer.
    pub validation: bool,
    /// Accumulate this many samples per pixel (default: the scene's spp).
    pub max_spp: Option<u32>,
    /// Start with the caustic and volume passes off (brute force).
    pub brute_force: bool,
    /// Where screenshots go.
    pub screenshot_dir: PathBuf,
    /// Steps to run (tests and automation).
    pub script: Vec<Step>,
}

/// What a viewer session did, for the caller's report.
#[derive(Debug, Default)]
pub struct ViewerSummary {
    /// Frames presented.
    pub frames: u64,
    /// Screenshots written (PNG paths).
    pub screenshots: Vec<PathBuf>,
    /// The validation counters (when validation was on).
    pub counters: Option<Arc<ValidationCounters>>,
}

/// Opens the window and runs until it is closed.
pub fn run(config: ViewerConfig) -> Result<ViewerSummary, ViewerError> {
    let event_loop = EventLoop::new().map_err(|e| ViewerError::NoDisplay(without_source_path(&e.to_string())))?;
    let mut app = App::new(config);
    event_loop.run_app(&mut app).map_err(|e| ViewerError::Window(e.to_string()))?;
    let summary = ViewerSummary {
        frames: app.frames,
        screenshots: std::mem::take(&mut app.screenshots),
        counters: app.counters.clone(),
    };
    // Vulkan objects go before the window they present to.
    app.gpu = None;
    match app.error.take() {
        Some(e) => Err(e),
        None => Ok(summary),
    }
}

/// The Vulkan objects of a window, dropped in field order: everything that
/// presents or renders before the device, the surface before the window.
struct WindowGpu {
    renderer: Option<Renderer>,
    swapchain: Option<Swapchain>,
    cmds: Commands,
    scene_gpu: GpuScene,
    device: Arc<Device>,
    surface: Surface,
    window: Arc<Window>,
}

/// What must be rebuilt before the next frame.
#[derive(Clone, Copy, Debug, Default)]
struct Dirty {
    swapchain: bool,
    renderer: bool,
    camera: bool,
}

struct App {
    config: ViewerConfig,
    scene: Scene,
    camera: CameraController,
    variant: RenderVariant,
    gpu: Option<WindowGpu>,
    counters: Option<Arc<ValidationCounters>>,
    dirty: Dirty,
    /// The frame on screen: its render output and displayed pixels.
    shown: Option<(RenderOutput, Vec<u8>)>,
    frames: u64,
    frames_at_wait: Option<u64>,
    frame_ms: f64,
    script: std::collections::VecDeque<Step>,
    screenshots: Vec<PathBuf>,
    drag: Option<(MouseButton, (f64, f64))>,
    cursor: (f64, f64),
    /// A size asked for and not yet reported by the window system.
    resize_pending: bool,
    /// The denoiser, loaded when the view first needs it; the reason it
    /// could not be, after which the view shows raw samples.
    denoiser: Option<Result<Denoiser, String>>,
    /// Show the current samples again (denoising was switched).
    refresh: bool,
    error: Option<ViewerError>,
}

impl App {
    fn new(config: ViewerConfig) -> Self {
        let scene = config.scene.clone();
        let variant =
            RenderVariant { caustics: !config.brute_force, volume: !config.brute_force, ..Default::default() };
        Self {
            camera: CameraController::new(&scene.camera),
            scene,
            variant,
            gpu: None,
            counters: None,
            dirty: Dirty::default(),
            shown: None,
            frames: 0,
            frames_at_wait: None,
            frame_ms: 0.0,
            script: config.script.iter().cloned().collect(),
            screenshots: Vec::new(),
            drag: None,
            cursor: (0.0, 0.0),
            resize_pending: false,
            denoiser: None,
            refresh: false,
            error: None,
            config,
        }
    }

    /// Samples per pixel the view accumulates.
    fn target_spp(&self) -> u32 {
        self.config.max_spp.unwrap_or(self.scene.image.spp).max(1)
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewerError) {
        log::error!("{e}");
        self.error = Some(e);
        event_loop.exit();
    }

    fn create_gpu(&mut self, event_loop: &ActiveEventLoop) -> Result<(), ViewerError> {
        let im = &self.scene.image;
        let attributes = Window::default_attributes()
            .with_title(format!("quadray — {}", self.config.name))
            .with_inner_size(PhysicalSize::new(im.width, im.height));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| ViewerError::Window(e.to_string()))?);
        let display = window.display_handle().map_err(|e| ViewerError::Window(e.to_string()))?.as_raw();
        let handle = window.window_handle().map_err(|e| ViewerError::Window(e.to_string()))?.as_raw();
        let instance = Arc::new(Instance::with_extensions(self.config.validation, &surface_extensions(display)?)?);
        self.counters = Some(instance.counters());
        let surface = Surface::new(&instance, display, handle)?;
        let device = Device::for_surface(instance, &surface)?;
        let mut cmds = Commands::new(&device)?;
        let mut scene_gpu = GpuScene::for_render(&device, &mut cmds, &self.scene)?;
        // The camera may be flown anywhere.
        scene_gpu.allow_far_rays();
        log::info!("viewer on {}", device.name);
        self.gpu = Some(WindowGpu { renderer: None, swapchain: None, cmds, scene_gpu, device, surface, window });
        self.dirty = Dirty { swapchain: true, renderer: true, camera: false };
        Ok(())
    }

    /// Applies an action.
    fn act(&mut self, event_loop: &ActiveEventLoop, action: Action) {
        match action {
            Action::CycleFilter => {
                self.scene.image.filter = self.scene.image.filter.next();
                self.dirty.renderer = true;
            }
            Action::NextPreset => {
                let next = self.scene.image.preset.map_or(Preset::Preview, Preset::next);
                self.set_preset(next);
            }
            Action::SetPreset(p) => self.set_preset(p),
            Action::ToggleCaustics => {
                self.variant.caustics = !self.variant.caustics;
                self.dirty.renderer = true;
            }
            Action::ToggleVolume => {
                self.variant.volume = !self.variant.volume;
                self.dirty.renderer = true;
            }
            Action::ToggleDenoise => {
                // The samples stay; only what is shown of them changes.
                self.scene.image.denoise = !self.scene.image.denoise;
                self.refresh = true;
            }
            Action::Screenshot(name) => {
                if let Err(e) = self.screenshot(name) {
                    self.fail(event_loop, e);
                }
            }
            Action::Capture(name) => {
                if let Err(e) = self.capture(&name) {
                    self.fail(event_loop, e);
                }
            }
            Action::ResetCamera => {
                self.camera.reset();
                self.dirty.camera = true;
            }
            Action::Fly(f, r, u) => {
                self.camera.fly(f, r, u);
                self.dirty.camera = true;
            }
            Action::Orbit(yaw, pitch) => {
                self.camera.orbit(yaw.to_radians(), pitch.to_radians());
                self.dirty.camera = true;
            }
            Action::Dolly(steps) => {
                self.camera.dolly(steps);
                self.dirty.camera = true;
            }
            Action::Resize(w, h) => {
                if let Some(g) = &self.gpu {
                    let now = g.window.inner_size();
                    let applied = g.window.request_inner_size(PhysicalSize::new(w, h));
                    // X11 answers later, with a Resized event.
                    self.resize_pending = applied.is_none() && (now.width, now.height) != (w, h);
                    self.dirty.swapchain |= applied.is_some();
                }
            }
            Action::Minimize(on) => {
                if let Some(g) = &self.gpu {
                    g.window.set_minimized(on);
                }
            }
            Action::Close => event_loop.exit(),
        }
        if let Some(g) = &self.gpu {
            g.window.request_redraw();
        }
    }

    fn set_preset(&mut self, preset: Preset) {
        let (w, h, seed, exposure) =
            (self.scene.image.width, self.scene.image.height, self.scene.image.seed, self.scene.image.exposure);
        let quality = self.scene.image.denoise_quality;
        self.scene.apply_preset(preset);
        (self.scene.image.width, self.scene.image.height, self.scene.image.seed, self.scene.image.exposure) =
            (w, h, seed, exposure);
        self.scene.image.denoise_quality = quality;
        self.dirty.renderer = true;
    }

    /// Writes the frame on screen: NAME.png (its displayed pixels) and
    /// NAME.exr (its linear radiance).
    fn screenshot(&mut self, name: Option<String>) -> Result<(), ViewerError> {
        let Some((out, _)) = &self.shown else {
            log::warn!("no frame on screen yet: no screenshot");
            return Ok(());
        };
        let dir = &self.config.screenshot_dir;
        let name = name.unwrap_or_else(|| {
            (1..)
                .map(|i| format!("{}-{i:03}", self.config.name))
                .find(|n| !dir.join(format!("{n}.png")).exists())
                .unwrap_or_default()
        });
        let png = dir.join(format!("{name}.png"));
        let exr = dir.join(format!("{name}.exr"));
        write_outputs(
            out,
            &[
                (png.clone(), OutputKind::Png { exposure: self.scene.image.exposure }),
                (exr, OutputKind::Exr(ExrPrecision::Float)),
            ],
        )
        .map_err(|source| ViewerError::Screenshot { path: png.clone(), source })?;
        eprintln!("screenshot: {} ({}x{}, {} spp)", png.display(), out.width, out.height, out.spp);
        self.screenshots.push(png);
        Ok(())
    }

    /// Writes NAME.png from the window's pixels as the X server has them.
    fn capture(&mut self, name: &str) -> Result<(), ViewerError> {
        let Some(g) = &self.gpu else { return Ok(()) };
        let size = g.window.inner_size();
        let handle = g.window.window_handle().map_err(|e| ViewerError::Window(e.to_string()))?.as_raw();
        let rgb = capture::capture_window(handle, (size.width, size.height)).map_err(ViewerError::Window)?;
        let path = self.config.screenshot_dir.join(format!("{name}.png"));
        image::save_buffer(&path, &rgb, size.width, size.height, image::ExtendedColorType::Rgb8).map_err(|e| {
            ViewerError::Screenshot { path: path.clone(), source: std::io::Error::other(e.to_string()) }
        })?;
        eprintln!("window capture: {} ({}x{})", path.display(), size.width, size.height);
        self.screenshots.push(path);
        Ok(())
    }

    /// Renders and presents one frame when there is something new to show.
    fn frame(&mut self) -> Result<(), ViewerError> {
        let target = self.target_spp();
        let Some(g) = &mut self.gpu else { return Ok(()) };
        if self.dirty.swapchain || g.swapchain.is_none() {
            let size = g.window.inner_size();
            g.swapchain = None;
            g.swapchain = Swapchain::new(&g.device, &g.surface, (size.width, size.height))?;
            self.dirty.swapchain = false;
            let Some(sc) = &g.swapchain else { return Ok(()) }; // minimised
            if (sc.extent.width, sc.extent.height) != (self.scene.image.width, self.scene.image.height) {
                self.scene.image.width = sc.extent.width;
                self.scene.image.height = sc.extent.height;
                self.dirty.renderer = true;
            }
        }
        if g.swapchain.is_none() {
            return Ok(());
        }
        self.camera.apply(&mut self.scene.camera);
        let start = Instant::now();
        if self.dirty.renderer || g.renderer.is_none() {
            g.renderer = None;
            g.renderer =
                Some(Renderer::with_samples(&g.device, &mut g.cmds, &g.scene_gpu, &self.scene, target, self.variant)?);
            self.dirty.renderer = false;
            self.dirty.camera = false;
            self.shown = None;
        }
        let renderer = g.renderer.as_mut().expect("built above");
        if self.dirty.camera {
            renderer.set_camera(&mut g.cmds, &g.scene_gpu, &self.scene)?;
            self.dirty.camera = false;
            self.shown = None;
        }
        let fresh = if renderer.samples() < target {
            renderer.add_samples(&mut g.cmds, 1, &mut |_, _| {})?;
            Some(renderer.output(&mut g.cmds)?)
        } else if self.refresh && renderer.samples() > 0 {
            Some(renderer.output(&mut g.cmds)?)
        } else {
            None
        };
        self.refresh = false;
        if let Some(mut out) = fresh {
            // The samples of the denoised frame on screen, if one is.
            let denoised_spp = self.shown.as_ref().filter(|(o, _)| o.denoised.is_some()).map(|(o, _)| o.spp);
            let showing_denoised = denoised_spp.is_some();
            // Denoised once the view rests (two samples, or all it will
            // get), then again each time its samples double.
            let due = denoised_spp.is_none_or(|n| out.spp >= target || out.spp >= 2 * n);
            let denoise = self.scene.image.denoise && (out.spp >= 2 || out.spp >= target);
            if denoise && due {
                if let Some(d) = Self::denoiser(&mut self.denoiser) {
                    match crate::jobs::denoise::denoise_output(d, &out, self.scene.image.denoise_quality) {
                        Ok(image) => out.denoised = Some(image),
                        Err(e) => {
                            log::warn!("{e}; showing the samples without denoising");
                            self.denoiser = Some(Err(e.to_string()));
                        }
                    }
                }
            }
            // While denoising, the last denoised frame of this view stays on
            // screen until the next is due.
            if out.denoised.is_some() || !(self.scene.image.denoise && showing_denoised) {
                let rgb = tone_map(&out, self.scene.image.exposure);
                let rgba = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
                self.shown = Some((out, rgba));
            }
        }
        let Some((_, rgba)) = &self.shown else { return Ok(()) };
        let swapchain = g.swapchain.as_mut().expect("checked above");
        if swapchain.present(&mut g.cmds, rgba)? == PresentResult::OutOfDate {
            self.dirty.swapchain = true;
        }
        self.frames += 1;
        self.frame_ms = start.elapsed().as_secs_f64() * 1e3;
        let denoised = match (&self.denoiser, self.scene.image.denoise) {
            (_, false) => "off".to_string(),
            (Some(Err(_)), true) => "unavailable".to_string(),
            _ => match &self.shown {
                Some((o, _)) if o.denoised.is_some() => format!("at {} spp", o.spp),
                _ => "on".to_string(),
            },
        };
        let title = format!(
            "quadray — {} — {} — filter {} — caustics {} — volume {} — denoise {} — {}/{} spp — {:.0} ms/frame",
            self.config.name,
            self.scene.image.preset.map_or("custom", Preset::name),
            self.scene.image.filter,
            if self.variant.caustics { "on" } else { "off" },
            if self.variant.volume { "on" } else { "off" },
            denoised,
            renderer.samples(),
            target,
            self.frame_ms
        );
        g.window.set_title(&title);
        Ok(())
    }

    /// The denoiser, loaded at the first call; `None` when the library is
    /// missing (said once, as a warning).
    fn denoiser(slot: &mut Option<Result<Denoiser, String>>) -> Option<&mut Denoiser> {
        let loaded = slot.get_or_insert_with(|| {
            Denoiser::load().map_err(|e| {
                log::warn!("{e}; the view shows the samples without denoising");
                e.to_string()
            })
        });
        loaded.as_mut().ok()
    }

    /// True while the view still has samples to add or changes to show.
    fn busy(&self) -> bool {
        let Some(g) = &self.gpu else { return false };
        if g.swapchain.is_none() && !self.dirty.swapchain {
            return false; // minimised: wait for the window to come back
        }
        let converged = g.renderer.as_ref().is_some_and(|r| r.samples() >= self.target_spp());
        self.dirty.renderer || self.dirty.camera || self.dirty.swapchain || self.refresh || !converged
    }

    /// Runs script steps until one has to wait.
    fn run_script(&mut self, event_loop: &ActiveEventLoop) {
        while let Some(step) = self.script.front().cloned() {
            let settled = !self.dirty.renderer
                && !self.dirty.camera
                && !self.dirty.swapchain
                && !self.resize_pending
                && self.shown.is_some();
            match step {
                Step::WaitSamples(n) => {
                    let have = self.shown.as_ref().map_or(0, |(o, _)| o.spp);
                    if !(settled && have >= n.min(self.target_spp())) {
                        return;
                    }
                }
                Step::WaitFrames(n) => {
                    let start = *self.frames_at_wait.get_or_insert(self.frames);
                    if self.frames < start + n as u64 {
                        if let Some(g) = &self.gpu {
                            g.window.request_redraw();
                        }
                        return;
                    }
                    self.frames_at_wait = None;
                }
                Step::Do(action) => {
                    if matches!(action, Action::Screenshot(_) | Action::Capture(_)) && !settled {
                        return;
                    }
                    self.act(event_loop, action);
                }
            }
            self.script.pop_front();
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_none() {
            if let Err(e) = self.create_gpu(event_loop) {
                self.fail(event_loop, e);
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) => {
                self.dirty.swapchain = true;
                self.resize_pending = false;
                if let Some(g) = &self.gpu {
                    g.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame() {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                let name = match &event.logical_key {
                    Key::Character(c) => Some(c.to_lowercase()),
                    Key::Named(NamedKey::Escape) => Some("escape".into()),
                    Key::Named(NamedKey::F12) => Some("f12".into()),
                    Key::Named(NamedKey::ArrowLeft) => Some("arrowleft".into()),
                    Key::Named(NamedKey::ArrowRight) => Some("arrowright".into()),
                    Key::Named(NamedKey::ArrowUp) => Some("arrowup".into()),
                    Key::Named(NamedKey::ArrowDown) => Some("arrowdown".into()),
                    _ => None,
                };
                if let Some(action) = name.as_deref().and_then(actions::key_action) {
                    self.act(event_loop, action);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.drag = (state == ElementState::Pressed).then_some((button, self.cursor));
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((button, last)) = self.drag {
                    let (dx, dy) = (position.x - last.0, position.y - last.1);
                    // Half a degree per pixel.
                    let (yaw, pitch) = (-dx * 0.5, dy * 0.5);
                    match button {
                        MouseButton::Left => self.act(event_loop, Action::Orbit(yaw, pitch)),
                        MouseButton::Right => {
                            self.camera.look(yaw.to_radians(), pitch.to_radians());
                            self.dirty.camera = true;
                        }
                        _ => {}
                    }
                    self.drag = Some((button, self.cursor));
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
                };
                self.act(event_loop, Action::Dolly(steps));
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        self.run_script(event_loop);
        if self.busy() {
            if let Some(g) = &self.gpu {
                g.window.request_redraw();
            }
        }
        event_loop.set_control_flow(ControlFlow::Wait);
    }
}
