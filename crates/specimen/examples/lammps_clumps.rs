//! A downstream DEM code's use of the library: 200 clones of the Ottawa-sand parents in
//! `fixtures/`, packed, checked, clumped, their LAMMPS clump data built in memory (→ stdout).
use specimen::{dem, place};
use std::{fs::File, io::BufReader};
const DIR: &str = "fixtures/grains/vcctl/ottawa-random"; // run from the workspace root

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut files: Vec<_> = std::fs::read_dir(DIR)?.collect::<Result<_, _>>()?;
    files.sort_by_key(std::fs::DirEntry::path);
    let mut grids = Vec::new();
    for f in files {
        let sh = sph_harmonics::vcctl::read_anm(BufReader::new(File::open(f.path())?))?;
        grids.push(cloner::grid_from_sh(&sh.to_model(sh.degree)?.0, 45, 1.1)?);
    }
    let parents = cloner::Parents::from_grids(grids, &morph_dna::MeasureParams::default())?;
    let (params, hooks) = (cloner::Params::default(), cloner::Hooks::default());
    let clones = specimen::clone_grains(&parents, &params, 200, 200, None, hooks)?;
    let shapes = clones.star_grains()?;
    let grains = clones.grains_of(&shapes);
    let packed = place::place_grains(
        &grains,
        None,
        Some((0.5, false)),
        place::Preset::Default,
        7,
        None,
    )?;
    let (poses, container) = (&packed.poses, &packed.container);
    specimen::check_grains(&grains, poses, container)?;
    let clump = levelset::ClumpParams::default();
    let (mut spheres, volumes) = specimen::shape_clumps(&clones, Some(&shapes), 45, 1.1, &clump)?;
    let (metres, of) = (1e-6, |k| clones.template_of(k)); // VCCTL scans are in micrometres
    let c = specimen::clump_templates(&mut spheres, &volumes, poses, of, container, metres, false)?;
    let s = dem::DemSpecimen {
        templates: &c.templates,
        bodies: &specimen::dem_bodies(poses, of, metres),
        container: &specimen::scale_container(container, metres),
        material: &dem::Material::default(),
        provenance: &[],
    };
    let mut data = Vec::new();
    dem::write_lammps_clump_data(&s, &mut data)?;
    std::io::Write::write_all(&mut std::io::stdout(), &data)?;
    Ok(())
}
