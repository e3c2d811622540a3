//! A loaded cell ([`Cell`]): its model, instrument, targets, working poses, obstacles and
//! data layout, and what it reads, builds and checks.

use super::*;

/// A loaded cell.
#[derive(Clone, Debug)]
pub struct Cell {
    /// Cell name (`name` at the top of the file, or the robot's name for a built-in cell).
    pub name: String,
    /// Where the cell came from (file path or `builtin:<robot>`).
    pub origin: String,
    /// The library robot or the robot the file describes, before instrument and targets.
    pub robot: Robot,
    /// The model: robot + instrument + targets, with parameter statuses applied.
    pub model: Model,
    /// `[instrument]`, if the cell has one.
    pub instrument: Option<Instrument>,
    /// `[[working]]` configurations, in file order.
    pub working: Vec<WorkingPose>,
    /// `[[working_path]]` paths, in file order.
    pub working_paths: Vec<WorkingPath>,
    /// `[[obstacles]]` the pose design keeps clear of, in the world frame.
    pub obstacles: Vec<Obstacle>,
    /// Capsules of the robot and of the tool (in chain frames).
    pub capsules: Vec<Capsule>,
    /// The safety margins planned poses keep (`[design]`, defaults without it).
    pub design: DesignClearance,
    /// What the instrument measures (`[parameters] measurement`; default pose if every
    /// target is a frame, else position).
    pub measurement: Measurement,
    /// `true`: the free set is reduced to the minimal identifiable set on load.
    pub auto_free: bool,
    /// Parameters the cell declared free (or with a prior) before any automatic reduction.
    pub declared_free: Vec<usize>,
    /// `[data] joints`: the data-file columns of the joints, if the cell names them.
    pub data_columns: Option<DataColumns>,
    /// How the controller's axis values map to the model's joints (`[robot.controller]`;
    /// a built-in robot's public vendor convention, else model angles): the angles of
    /// controller programs, and of data files with `[data] angles = "controller"`.
    pub controller: crate::model::controller::ControllerConvention,
    /// Things the user should know that do not stop the cell from loading.
    pub warnings: Vec<String>,
    /// The link form the cell asked for (`[robot] convention`, default `auto`).
    pub form: LinkForm,
    /// Links that form changed (Hayati / β across nearly parallel axes).
    pub form_changes: Vec<FormChange>,
    /// Nearly parallel axes the model still has no tilt parameter for, with the fix.
    pub form_incomplete: Vec<String>,
    /// The stated uncertainty of the parameters a fit holds fixed (`[parameters]
    /// fixed_prior`, `fixed_priors`): the model floor of the TCP covariance
    /// ([`crate::identify::model_floor`]).
    pub fixed_prior: crate::model::prior::FixedPrior,
}

impl Cell {
    /// How this cell's data files are laid out: its `[data]` section, or armcal's own CSV.
    pub fn data_format(&self) -> crate::measure::format::DataFormat {
        use crate::measure::format::DataFormat;
        let mut format = self
            .data_columns
            .as_ref()
            .map_or_else(DataFormat::armcal, |d| d.format.clone());
        format.controller_columns = DataFormat::armcal_for(&self.controller).controller_columns;
        format
    }

    /// armcal's joint CSV `text` (a pose list, design, data file or compensated program) as
    /// this cell writes it: with the controller's axis columns (`q2_controller_deg`) after
    /// the model's when the cell's `[robot.controller]` is not the identity
    /// ([`crate::measure::csv::with_controller_columns`]); else `text` itself.
    pub fn with_controller_columns(&self, text: String) -> Result<String, Error> {
        if self.controller.is_identity() {
            return Ok(text);
        }
        crate::measure::csv::with_controller_columns(
            &text,
            "armcal's output",
            &self.model,
            &self.controller,
        )
    }

    /// The instrument's noise model; [`NoiseModel::default`] for a cell without an
    /// instrument.
    pub fn noise(&self) -> NoiseModel {
        self.instrument
            .as_ref()
            .map(|i| i.noise.clone())
            .unwrap_or_default()
    }

    /// Every configuration the pose-design KPIs take the TCP at, with its weight in the mean
    /// KPI: the working poses (their weight), then each working path's configurations (the
    /// path's weight shared equally among them).
    pub fn kpi_configurations(&self) -> Vec<(&[f64], f64)> {
        let poses = self.working.iter().map(|w| (w.q.as_slice(), w.weight));
        let paths = self.working_paths.iter().flat_map(|p| {
            let share = p.weight / p.q.len() as f64;
            p.q.iter().map(move |q| (q.as_slice(), share))
        });
        poses.chain(paths).collect()
    }

    /// Reads a cell file.
    pub fn from_file(path: &Path) -> Result<Cell, Error> {
        let text =
            crate::input::read_capped(path, crate::input::TEXT_CAP).map_err(|e| Error::File {
                file: path.display().to_string(),
                message: e.to_string(),
            })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Cell::from_toml(&text, &path.display().to_string(), &dir)
    }

    /// Parses a cell from TOML text; `file` names it in errors, `dir` resolves relative
    /// paths (URDF). The format, every field with its unit and default, is the guide's
    /// "Cell file" reference page (`docs/`).
    ///
    /// ```
    /// use armcal::Cell;
    ///
    /// // A two-link planar arm written as a DH table (lengths mm, angles deg) and one reflector.
    /// let text = r#"
    /// name = "planar"
    /// [robot]
    /// name = "planar-2r"
    /// [[robot.links]]
    /// convention = "dh"
    /// joint = "revolute"
    /// limits = [-170, 170]
    /// theta_deg = 0
    /// d_mm = 0
    /// a_mm = 400
    /// alpha_deg = 0
    /// [[robot.links]]
    /// convention = "dh"
    /// joint = "revolute"
    /// limits = [-150, 150]
    /// theta_deg = 0
    /// d_mm = 0
    /// a_mm = 300
    /// alpha_deg = 0
    /// [[targets]]
    /// name = "smr"
    /// xyz_mm = [50, 0, 0]
    /// "#;
    /// let cell = Cell::from_toml(text, "planar.toml", ".".as_ref()).unwrap();
    /// assert_eq!(cell.model.dof(), 2);
    ///
    /// // A mistake is an error naming the file, the line and the field.
    /// let wrong = text.replace("a_mm = 300", "a_mm = \"300\"");
    /// let message = Cell::from_toml(&wrong, "planar.toml", ".".as_ref()).unwrap_err().to_string();
    /// assert!(message.contains("planar.toml"), "{message}");
    /// ```
    pub fn from_toml(text: &str, file: &str, dir: &Path) -> Result<Cell, Error> {
        raw::parse(text, file, dir)
    }

    /// A cell with only a library robot in its complete, minimal form ([`LinkForm::Auto`]):
    /// the tool frame is measured as a full pose, all parameters free.
    pub fn from_robot(name: &str) -> Result<Cell, Error> {
        let mut robot = robots::robot(name)?;
        let given = Model::from_spec(&robot.spec)?;
        let spec = robot.spec.clone();
        let shaped = shape_robot(&mut robot, &given, spec, LinkForm::Auto, &mut Vec::new())?;
        let model = Model::from_spec(&shaped.spec)?;
        let declared_free = model.registry.free();
        let controller =
            robots::controller::vendor_convention(name, model.dof()).unwrap_or_else(|_| {
                crate::model::controller::ControllerConvention::model_angles(model.dof())
            });
        Ok(Cell {
            name: robot.name.clone(),
            origin: format!("builtin:{name}"),
            capsules: robot.capsules.clone(),
            robot,
            model,
            instrument: None,
            working: Vec::new(),
            working_paths: Vec::new(),
            obstacles: Vec::new(),
            design: DesignClearance::default(),
            measurement: Measurement::Pose,
            auto_free: false,
            declared_free,
            data_columns: None,
            controller,
            warnings: Vec::new(),
            form: LinkForm::Auto,
            form_changes: shaped.changes,
            form_incomplete: shaped.incomplete,
            fixed_prior: crate::model::prior::FixedPrior::default(),
        })
    }

    /// A cell from a robot name or a cell-file path: a path if it exists or ends in
    /// `.toml`, a library robot otherwise.
    pub fn load(name_or_path: &str) -> Result<Cell, Error> {
        let p = PathBuf::from(name_or_path);
        if p.exists() || name_or_path.ends_with(".toml") {
            Cell::from_file(&p)
        } else {
            Cell::from_robot(name_or_path)
        }
    }

    /// Identifiability of the parameters the cell declared free, with the cell's
    /// measurement type unless `opts` says otherwise.
    pub fn identifiability(
        &self,
        opts: &IdentifiabilitySettings,
    ) -> Result<identifiability::Identifiability, Error> {
        let declared = self.declared_model();
        identifiability::analyze(&declared, &declared.nominal(), opts)
    }

    /// Why `report` (an analysis of this cell's declared free set) finds fewer parameters
    /// than the generic count, if it does; `configurations` are the data's, if the analysis
    /// was at a data set's configurations.
    pub fn rank_deficit(
        &self,
        report: &identifiability::Identifiability,
        params: &[f64],
        configurations: Option<&[Vec<f64>]>,
    ) -> Result<Option<RankDeficit>, Error> {
        let declared = self.declared_model();
        rank_deficit(
            &declared,
            params,
            report.count(&declared).geometric,
            report.measurement,
            configurations,
        )
    }

    /// The model with every parameter the cell declared free (or with a prior) free again,
    /// before any automatic reduction.
    pub fn declared_model(&self) -> Model {
        let mut declared = self.model.clone();
        for &i in &self.declared_free {
            if !declared.registry.get(i).status.is_free() {
                declared.registry.set_status(i, ParameterStatus::Free);
            }
        }
        declared
    }

    /// This cell with its instrument repeated at each of `stations`
    /// ([`Model::with_stations`]; its model and declared free set follow); empty: the cell
    /// as it is.
    pub fn with_stations(&self, stations: &[String]) -> Result<Cell, Error> {
        if stations.is_empty() {
            return Ok(self.clone());
        }
        let model = self.model.with_stations(stations)?;
        let declared_free = (0..model.param_count())
            .filter(|&i| {
                self.declared_free
                    .contains(&self.model.station_source(&model, i))
            })
            .collect();
        Ok(Cell {
            model,
            declared_free,
            ..self.clone()
        })
    }

    /// Default analysis options for this cell (its measurement type).
    pub fn identifiability_settings(&self) -> IdentifiabilitySettings {
        IdentifiabilitySettings {
            measurement: self.measurement,
            ..Default::default()
        }
    }
}
