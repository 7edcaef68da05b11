//! Stages 3–5 of `process` outdoors: irradiance and pseudo-albedos from the
//! training views under the measured light (thesis §5.2, §5.4), then the
//! held-out views re-rendered under the *predicted* light (§5.5), with the
//! texture finer than the grid that the training photographs show (§5.6.4,
//! eq. 5.16, [`campanile_process::outdoor::texture_transfer`]), and
//! compared with what the camera saw (the grid-only figure is reported too).
//! Zoom photographs (views taken at their own focal length) are kept out of
//! the fit and the held-out comparison: each gets the high-resolution
//! pseudo-albedos of eq. (5.16) at its own pixels, and a re-render with
//! them at its own time under its occurrence's light, against itself.

use std::collections::BTreeMap;
use std::time::Instant;

use crate::Result;
use anyhow::{Context, anyhow};
use campanile_config::scene::MaterialModel;
use campanile_process::camera::image::RadianceImage;
use campanile_process::outdoor::novel_view::{NovelView, compare_view, render_view};
use campanile_process::outdoor::rerender::{Reference, relative_rmse};
use campanile_process::outdoor::texture_transfer::texture_sources;
use campanile_process::outdoor::zoom_albedo::ZoomAlbedo;
use campanile_process::outdoor::{
    Illumination, Photo, Reflectance, ReflectanceSettings, RerenderSettings, ZoomSettings, recover_reflectance,
    rerender, rerender_zoom, zoom_albedo,
};
use campanile_process::pipeline::{
    EstimateSettings, EstimatedLight, KnownLight, MeasuredSky, MergedGroup, OccurrenceLight, Purpose, ScaleSource,
    estimated_light, mean_time, measured_sky, predicted_estimated_light, predicted_sky,
};
use campanile_process::render::{CameraRig, Scene};
use campanile_process::sky::Atmosphere;
use campanile_process::sun::sun_position;
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

use super::Processed;

/// A held-out view, measured and re-rendered.
pub struct HeldOutView {
    /// The group's key.
    pub label: String,
    /// What the camera saw (HDR).
    pub measured: RadianceImage,
    /// The re-render under the predicted light, with the texture of the
    /// training photographs from the same camera (eq. 5.16) where there are any.
    pub rendered: RadianceImage,
    /// Training photographs from this very camera whose texture the
    /// re-render carries (§5.6.4); 0: the grid's pseudo-albedos alone.
    pub references: usize,
    /// Relative RMSE of 4×4-pixel block means of the grid-only re-render
    /// (no photo's texture, §5.5) over the mask.
    pub rmse_block_grid: f64,
    /// Pixels on the target surfaces, valid in the measurement.
    pub mask: Vec<bool>,
    /// Relative RMSE per pixel over the mask.
    pub rmse_pixel: f64,
    /// Relative RMSE of 4×4-pixel block means over the mask.
    pub rmse_block: f64,
}

/// A zoom photograph's view (thesis §5.6.4): its high-resolution
/// pseudo-albedos, and the view re-rendered with them at its own time.
pub struct ZoomView {
    /// The group's key.
    pub label: String,
    /// The pseudo-albedos at the photograph's pixels (eq. 5.16), with what
    /// became of each pixel.
    pub albedo: ZoomAlbedo,
    /// Where the light came from: measured at its occurrence, or predicted
    /// (a held-out occurrence).
    pub light: &'static str,
    /// The view re-rendered with its own pseudo-albedos under that light.
    pub rendered: RadianceImage,
    /// Relative RMSE of 4×4-pixel block means of the re-render against the
    /// photograph, over the target pixels valid in it.
    pub rmse_block: f64,
    /// Blocks compared.
    pub blocks: usize,
    /// The same with the grid's pseudo-albedos alone (no eq. 5.16).
    pub rmse_block_grid: f64,
    /// Relative RMSE per pixel of the re-render, and of the grid-only one.
    pub rmse_pixel: f64,
    pub rmse_pixel_grid: f64,
}

/// What the outdoor stages made.
pub struct OutdoorProducts {
    /// The pseudo-albedos and their diagnostics.
    pub reflectance: Reflectance,
    /// The held-out views.
    pub held_out: Vec<HeldOutView>,
    /// The training occurrences whose sun or sky was estimated rather
    /// than measured, and how.
    pub estimated: Vec<(String, EstimatedLight)>,
    /// Held-out views lit by the clear-sky model scaled as the estimated
    /// training lights were (no measured light to predict from).
    pub predicted_from_model: Vec<String>,
    /// The zoom photographs' views.
    pub zoom: Vec<ZoomView>,
    /// Stage times.
    pub seconds: Vec<(String, f64)>,
}

/// The surfaces that get pseudo-albedos: those whose material is a
/// pseudo-BRDF (§5.2), except the ground, which lights them as environment.
pub fn targets(p: &Processed, scene: &Scene) -> Result<Vec<usize>> {
    let (description, _) = p
        .inputs
        .scene
        .as_ref()
        .ok_or_else(|| anyhow!("the session has no scene: pseudo-albedos need its geometry"))?;
    let pseudo: Vec<&str> = description
        .materials
        .iter()
        .filter(|m| m.model == MaterialModel::PseudoBrdf)
        .map(|m| m.name.as_str())
        .collect();
    description
        .surfaces
        .iter()
        .filter(|s| pseudo.contains(&s.material.as_str()) && s.name != "ground")
        .map(|s| {
            scene
                .surface_index(&s.name)
                .ok_or_else(|| anyhow!("surface {:?} is not in the scene's geometry", s.name).into())
        })
        .collect()
}

/// The camera of merged group `g` (its head pose and the station's mount,
/// or a photograph's own orientation when it was taken off the head).
pub fn rig_of(p: &Processed, g: &MergedGroup) -> CameraRig {
    CameraRig {
        pinhole: g.pinhole,
        mount: g.mount(&p.optics.mount),
        head: g.head,
        position: Vector3::from(g.position_m),
        width: g.map.width,
        height: g.map.height,
    }
}

fn photo_of(p: &Processed, g: &MergedGroup, time: DateTime<Utc>) -> Photo {
    Photo {
        label: g.key.clone(),
        image: RadianceImage {
            width: g.map.width,
            height: g.map.height,
            data: g.map.rgb.clone(),
        },
        rig: rig_of(p, g),
        time,
        mask: Some(g.map.mask.iter().map(|&m| m == 0).collect()),
    }
}

/// Pseudo-albedos from the training views, then the held-out views.
pub fn outdoor(p: &Processed, scene: &Scene, settings: &ReflectanceSettings) -> Result<OutdoorProducts> {
    let targets = targets(p, scene)?;
    let mut seconds = Vec::new();
    let t = Instant::now();
    // One illumination per training occurrence, at the mean time of its
    // views (within a minute or two of each), the sun where it was then.
    let mut by_occurrence: BTreeMap<&str, Vec<&MergedGroup>> = BTreeMap::new();
    for g in &p.merged {
        if matches!(g.purpose, Purpose::View { .. }) && !g.zoom {
            by_occurrence.entry(&g.occurrence).or_default().push(g);
        }
    }
    let mut skies: Vec<(DateTime<Utc>, MeasuredSky)> = Vec::new();
    let mut estimated: Vec<(String, EstimatedLight)> = Vec::new();
    let estimate = EstimateSettings {
        spacing_m: settings.spacing_m,
        gather: settings.gather,
        footprint: settings.footprint,
        ..EstimateSettings::default()
    };
    let mut photos = Vec::new();
    for (occurrence, groups) in &by_occurrence {
        let Some(light) = p.light.iter().find(|l| l.occurrence == *occurrence) else {
            continue;
        };
        if light.held_out {
            continue;
        }
        let time = mean_time(&groups.iter().map(|g| g.time).collect::<Vec<_>>());
        let sun = sun_position(time, &p.optics.observer, p.optics.delta_t_s)
            .map_err(|e| anyhow!("sun position at {time}: {e}"))?;
        let here: Vec<Photo> = groups.iter().map(|g| photo_of(p, g, time)).collect();
        let sky = if light.sky.is_some() && light.sun_irradiance.is_some() {
            let mut sky = measured_sky(light).with_context(|| format!("the light of {occurrence}"))?;
            sky.sun_direction = sun.direction();
            sky
        } else {
            // No sky scan or no sun shot: the clear-sky model, split by the
            // photographs' sunlit/shadowed ratio (pipeline::estimated_light).
            let est = estimated_light(
                scene,
                &targets,
                &here,
                &known_light(light, sun.direction()),
                time,
                &estimate,
            )
            .map_err(|e| anyhow!("estimating the light of {occurrence}: {e}"))?;
            let sky = est.sky.clone();
            estimated.push(((*occurrence).to_owned(), est));
            sky
        };
        skies.push((time, sky));
        photos.extend(here);
    }
    let lights: Vec<Illumination> = skies
        .iter()
        .map(|(time, sky)| Illumination { time: *time, sky })
        .collect();
    let (reflectance, _) =
        recover_reflectance(scene, &targets, &photos, &lights, settings).map_err(|e| anyhow!("pseudo-albedos: {e}"))?;
    seconds.push((
        format!(
            "irradiance and pseudo-albedos ({} photos, {} cells)",
            photos.len(),
            reflectance.cells.len()
        ),
        t.elapsed().as_secs_f64(),
    ));

    let t = Instant::now();
    // Photos the fit rejected (a wrong exposure, …) lend no texture.
    let references: Vec<Reference> = photos
        .iter()
        .filter(|photo| !reflectance.photos.iter().any(|c| c.label == photo.label && c.outlier))
        .filter_map(|photo| {
            lights
                .iter()
                .find(|l| l.time == photo.time)
                .map(|light| Reference { photo, light })
        })
        .collect();
    let sources = texture_sources(scene, &reflectance, &references, &RerenderSettings::default());
    let mut held_out = Vec::new();
    let mut predicted_from_model = Vec::new();
    for g in p
        .merged
        .iter()
        .filter(|g| g.held_out && !g.zoom && matches!(g.purpose, Purpose::View { .. }))
    {
        let (sky, from_model) = predicted_light(p, g, &estimated)?;
        if from_model {
            predicted_from_model.push(g.key.clone());
        }
        let rig = rig_of(p, g);
        let light = Illumination {
            time: g.time,
            sky: &sky,
        };
        let view = render_view(
            scene,
            &reflectance,
            &rig,
            &light,
            &sources,
            &RerenderSettings::default(),
        );
        let measured = RadianceImage {
            width: g.map.width,
            height: g.map.height,
            data: g.map.rgb.clone(),
        };
        let valid: Vec<bool> = g.map.mask.iter().map(|&m| m == 0).collect();
        let c = compare_view(scene, &reflectance, &rig, &view, &measured, Some(&valid));
        held_out.push(HeldOutView {
            references: view.references,
            rmse_block_grid: c.rmse_block_grid,
            label: g.key.clone(),
            measured,
            rendered: view.rendered,
            mask: c.mask,
            rmse_pixel: c.rmse_pixel,
            rmse_block: c.rmse_block,
        });
    }
    seconds.push((
        format!("held-out re-renders ({})", held_out.len()),
        t.elapsed().as_secs_f64(),
    ));

    let t = Instant::now();
    let mut zoom = Vec::new();
    for g in p
        .merged
        .iter()
        .filter(|g| g.zoom && matches!(g.purpose, Purpose::View { .. }))
    {
        zoom.push(zoom_view(p, scene, &reflectance, g, &estimated)?);
    }
    if !zoom.is_empty() {
        seconds.push((
            format!("zoom photographs' pseudo-albedos ({})", zoom.len()),
            t.elapsed().as_secs_f64(),
        ));
    }
    Ok(OutdoorProducts {
        reflectance,
        held_out,
        estimated,
        predicted_from_model,
        zoom,
        seconds,
    })
}

/// The light at `g`'s time: its occurrence's measured sun and sky (the
/// sun moved to that time), or, for a held-out occurrence or one without a
/// sky scan and sun shot, [`predicted_light`]. Says which.
fn light_at(
    p: &Processed,
    g: &MergedGroup,
    estimated: &[(String, EstimatedLight)],
) -> Result<(MeasuredSky, &'static str)> {
    let own = p
        .light
        .iter()
        .find(|l| l.occurrence == g.occurrence && !l.held_out && l.sky.is_some() && l.sun_irradiance.is_some());
    if let Some(l) = own {
        let sun = sun_position(g.time, &p.optics.observer, p.optics.delta_t_s)
            .map_err(|e| anyhow!("sun position at {}: {e}", g.time))?;
        let mut sky = measured_sky(l).with_context(|| format!("the light of {}", g.occurrence))?;
        sky.sun_direction = sun.direction();
        return Ok((sky, "measured"));
    }
    let (sky, from_model) = predicted_light(p, g, estimated)?;
    Ok((
        sky,
        if from_model {
            "predicted from the clear-sky model"
        } else {
            "predicted"
        },
    ))
}

/// The light at `g`'s time predicted from the measured ones (§5.5.1), or,
/// with no measured light to predict from, the clear-sky model scaled as
/// the estimated training lights were (those not scaled to a fitted sky;
/// then `true`).
fn predicted_light(
    p: &Processed,
    g: &MergedGroup,
    estimated: &[(String, EstimatedLight)],
) -> Result<(MeasuredSky, bool)> {
    let sun = sun_position(g.time, &p.optics.observer, p.optics.delta_t_s)
        .map_err(|e| anyhow!("sun position at {}: {e}", g.time))?;
    match predicted_sky(&p.light, &sun) {
        Ok(sky) => Ok((sky, false)),
        Err(_) if !estimated.is_empty() => {
            let from_model: Vec<&EstimatedLight> = estimated
                .iter()
                .map(|(_, e)| e)
                .filter(|e| e.scale != ScaleSource::FittedSky)
                .collect();
            Ok((
                predicted_estimated_light(&from_model, sun.direction(), &Atmosphere::clear()),
                true,
            ))
        }
        Err(e) => Err(anyhow!(e).context(format!("predicting the light of {}", g.key)).into()),
    }
}

/// A zoom photograph's high-resolution pseudo-albedos (eq. 5.16) from the
/// grid's, and its view re-rendered with them (and with the grid's alone)
/// at its own time, against the photograph.
fn zoom_view(
    p: &Processed,
    scene: &Scene,
    refl: &Reflectance,
    g: &MergedGroup,
    estimated: &[(String, EstimatedLight)],
) -> Result<ZoomView> {
    let (sky, light_from) = light_at(p, g, estimated)?;
    let light = Illumination {
        time: g.time,
        sky: &sky,
    };
    let photo = photo_of(p, g, g.time);
    let albedo = zoom_albedo(scene, refl, &photo, &light, &ZoomSettings::default())
        .map_err(|e| anyhow!("zoom photograph {}: {e}", g.key))?;
    let settings = RerenderSettings::default();
    let rendered = rerender_zoom(scene, refl, &albedo, &light, &settings);
    let (grid_only, _) = rerender(scene, refl, &photo.rig, &light, &settings);
    let view = NovelView {
        grid_only,
        rendered,
        references: 0,
    };
    let c = compare_view(scene, refl, &photo.rig, &view, &photo.image, photo.mask.as_deref());
    Ok(ZoomView {
        label: g.key.clone(),
        light: light_from,
        rmse_block: c.rmse_block,
        blocks: c.blocks,
        rmse_block_grid: c.rmse_block_grid,
        rmse_pixel: c.rmse_pixel,
        rmse_pixel_grid: relative_rmse(&view.grid_only, &photo.image, &c.mask).unwrap_or(f64::NAN),
        albedo,
        rendered: view.rendered,
    })
}

/// What was measured of an occurrence's light.
fn known_light(l: &OccurrenceLight, sun_direction: [f64; 3]) -> KnownLight {
    KnownLight {
        sun_direction,
        sky: match l.sky.as_deref() {
            Some([r, g, b]) => Some([r.fit.model, g.fit.model, b.fit.model]),
            _ => None,
        },
        sun_irradiance: l.sun_irradiance.as_ref().map(|s| s.irradiance),
    }
}
