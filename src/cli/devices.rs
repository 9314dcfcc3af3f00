//! `quadray devices`: the Vulkan devices and what each offers the renderer.

use anyhow::{Context as _, Result};
use clap::Parser;
use quadray::vk::{Backend, Capabilities, SETUP_HINT};
use serde::Serialize;

#[derive(Parser, Debug)]
pub(crate) struct DevicesArgs {
    /// Print JSON for scripts: `devices` (every field below, per device, with
    /// what it lacks for each backend) and `auto` (the device index and
    /// backend a render would use; null when none fits).
    #[arg(long)]
    pub(crate) json: bool,
}

/// One device in the JSON: its capabilities, what it lacks per backend and
/// the backend `auto` would take on it.
#[derive(Serialize)]
struct DeviceEntry<'a> {
    #[serde(flatten)]
    capabilities: &'a Capabilities,
    lacks: std::collections::BTreeMap<&'static str, Vec<&'static str>>,
    auto_backend: Option<Backend>,
}

#[derive(Serialize)]
struct Auto<'a> {
    index: usize,
    device: &'a str,
    backend: Backend,
}

#[derive(Serialize)]
struct Report<'a> {
    devices: Vec<DeviceEntry<'a>>,
    auto: Option<Auto<'a>>,
}

fn yes(flag: bool) -> &'static str {
    if flag {
        "yes"
    } else {
        "no"
    }
}

/// `quadray devices`.
pub(crate) fn devices(args: DevicesArgs) -> Result<()> {
    let driver = quadray::vk::runtime::driver();
    if !args.json {
        let hint = match driver {
            quadray::vk::runtime::Driver::Runtime(_) => " (--system-vulkan for the system's)",
            quadray::vk::runtime::Driver::System => "",
        };
        println!("Vulkan: {}{hint}", quadray::vk::runtime::describe(&driver));
    }
    let quadray::vk::Survey { devices, auto } = quadray::vk::survey().context("cannot list the Vulkan devices")?;
    if args.json {
        let report = Report {
            devices: devices
                .iter()
                .map(|c| DeviceEntry {
                    capabilities: c,
                    lacks: Backend::ALL.into_iter().map(|b| (b.name(), c.lacks(b))).collect(),
                    auto_backend: c.auto_backend(),
                })
                .collect(),
            auto: auto.map(|(index, backend)| Auto { index, device: &devices[index].name, backend }),
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    if devices.is_empty() {
        println!("the Vulkan loader lists no devices");
    }
    for (index, c) in devices.iter().enumerate() {
        println!(
            "{index}: {} ({}, Vulkan {}, driver {}: {})",
            c.name, c.device_type, c.api_version, c.driver_name, c.driver_info
        );
        let pipeline = match c.pipeline_limits {
            Some(l) => format!(
                "yes (group handles {} B, handle alignment {}, base alignment {}, recursion up to {}, hit attributes up to {} B)",
                l.shader_group_handle_size,
                l.shader_group_handle_alignment,
                l.shader_group_base_alignment,
                l.max_ray_recursion_depth,
                l.max_ray_hit_attribute_size
            ),
            None => "no".into(),
        };
        println!("   ray queries: {}; ray-tracing pipelines: {pipeline}", yes(c.ray_query));
        println!(
            "   acceleration structures: {}; float64: {}; 64-bit atomics: {}; timestamps: {}",
            yes(c.acceleration_structure),
            yes(c.float64),
            yes(c.int64 && c.int64_atomics),
            if c.timestamps { format!("yes ({} ns a tick)", c.timestamp_period_ns) } else { "no".into() },
        );
        for line in c.backend_lines() {
            println!("   backend {line}");
        }
    }
    match auto {
        Some((index, backend)) => println!("auto: device {index} ({}) with the {backend} backend", devices[index].name),
        None => println!("auto: no device fits this build's backends. To fix: {SETUP_HINT}"),
    }
    Ok(())
}
