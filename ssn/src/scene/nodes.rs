//! Dofs named by node and component: with `[model] dof_map = "FILE"`, a `[[contact.point]]`,
//! a `[[friction.point]]` or `[output]` may give `node` and `component` (1, 2, 3 for x, y,
//! z; up to 6 for rotations) instead of `dof`, and lists `nodes` and `components` instead of
//! `dofs`; each is resolved through the map to its matrix row, as if the row's 1-based
//! `dof` had been given.

use super::check::Check;
use super::*;

/// What a dof may be given as, for messages.
const BY_NODE: &str = "`node` with `component` (1, 2, 3: x, y, z) once [model] has \
                       `dof_map = \"FILE\"` (a file naming each matrix row's node and \
                       component)";

impl Check<'_> {
    /// The 1-based dof of `section`'s `dof`, or of its `node` and `component` through the
    /// dof map (`None`: neither given); refuses both forms together.
    pub(super) fn address(
        &self,
        section: &str,
        dof: Option<i64>,
        node: Option<i64>,
        component: Option<i64>,
    ) -> Result<Option<i64>, SceneError> {
        let key = |name: &str| format!("{section}.{name}");
        match (dof, node, component) {
            (Some(_), Some(_), _) => Err(self.invalid(
                &key("node"),
                "given together with `dof`",
                "either `dof` (a 1-based matrix row) or `node` and `component` (through the \
                 [model] dof_map)",
            )),
            (_, None, Some(c)) => Err(self.invalid(
                &key("component"),
                format!("{c} without `node`"),
                "`component` together with `node`",
            )),
            (dof, None, None) => Ok(dof),
            (None, Some(node), component) => self
                .resolve(&key("node"), &key("component"), node, component)
                .map(Some),
        }
    }

    /// The 1-based dofs of a list of `dofs`, or of `nodes` with `components` (one each)
    /// through the dof map (`None`: neither given), and the key of the list given.
    pub(super) fn addresses(
        &self,
        keys: [String; 3],
        dofs: Option<&[i64]>,
        nodes: Option<&[i64]>,
        components: Option<&[i64]>,
    ) -> Result<Option<(Vec<i64>, String)>, SceneError> {
        let [dofs_key, nodes_key, components_key] = keys;
        match (dofs, nodes, components) {
            (Some(_), Some(_), _) => Err(self.invalid(
                &nodes_key,
                format!("given together with `{dofs_key}`"),
                &format!("either `{dofs_key}` or `{nodes_key}` with `{components_key}`"),
            )),
            (_, None, Some(_)) => Err(self.invalid(
                &components_key,
                format!("given without `{nodes_key}`"),
                &format!("`{components_key}` together with `{nodes_key}`"),
            )),
            (dofs, None, None) => Ok(dofs.map(|d| (d.to_vec(), dofs_key))),
            (None, Some(nodes), components) => {
                let components = components.unwrap_or(&[]);
                if components.len() != nodes.len() {
                    return Err(self.invalid(
                        &components_key,
                        format!("{} values", components.len()),
                        &format!("one component per node ({} values)", nodes.len()),
                    ));
                }
                let dofs = nodes
                    .iter()
                    .zip(components)
                    .map(|(&n, &c)| self.resolve(&nodes_key, &components_key, n, Some(c)))
                    .collect::<Result<Vec<_>, _>>()?;
                Ok(Some((dofs, nodes_key)))
            }
        }
    }

    /// The 1-based dof of `node`'s `component` in the dof map: refused without a map, for a
    /// node the map does not name, or a component it does not give that node.
    pub(super) fn resolve(
        &self,
        node_key: &str,
        component_key: &str,
        node: i64,
        component: Option<i64>,
    ) -> Result<i64, SceneError> {
        let Some(map) = self.dof_map() else {
            return Err(self.invalid(
                node_key,
                format!("{node} without [model] dof_map"),
                &format!("`dof` (1-based, as in Matrix Market), or {BY_NODE}"),
            ));
        };
        let file = map.path.display();
        let components = u64::try_from(node).map_or_else(|_| Vec::new(), |n| map.map.components(n));
        if components.is_empty() {
            let (first, last) = map.map.node_range().unwrap_or((1, 0));
            return Err(self.invalid(
                node_key,
                node,
                &format!("a node of the dof map {file} (its nodes lie in {first}..={last})"),
            ));
        }
        let listed = || {
            let c: Vec<String> = components.iter().map(u8::to_string).collect();
            format!(
                "a component the dof map {file} gives node {node}: {} (1, 2, 3: x, y, z)",
                c.join(", ")
            )
        };
        let Some(component) = component else {
            return Err(self.invalid(component_key, "missing", &listed()));
        };
        match u8::try_from(component) {
            Ok(c) if components.contains(&c) => {
                let row = map
                    .map
                    .row(node as u64, c)
                    .expect("a listed component has a row");
                Ok(row as i64 + 1)
            }
            _ => Err(self.invalid(component_key, component, &listed())),
        }
    }

    /// `[output]` of a `[model]` scene: `dof`, or `node` and `component`; 0-based.
    pub(super) fn model_output(&self, o: RawOutput) -> Result<usize, SceneError> {
        let dof = self.address("output", o.dof, o.node, o.component)?;
        let dof = dof.ok_or_else(|| {
            self.invalid(
                "output.dof",
                "missing",
                &format!("a 1-based dof number, or {BY_NODE}"),
            )
        })?;
        Ok(self.count("output.dof", dof, 1, usize::MAX >> 1)? - 1)
    }

    /// `[output] dof` of a built-in structure (`[rod]`, `[bladed_disk]`: no dof map),
    /// `1..=dofs`, 0-based.
    pub(super) fn output_dof(&self, o: RawOutput, dofs: usize) -> Result<usize, SceneError> {
        if let Some(key) = [("output.node", o.node), ("output.component", o.component)]
            .iter()
            .find_map(|(key, v)| v.map(|_| key))
        {
            return Err(self.invalid(
                key,
                "given for a built-in structure",
                "`dof` (node and component name dofs of a [model] with a dof_map)",
            ));
        }
        let dof = o.dof.ok_or_else(|| {
            self.invalid(
                "output.dof",
                "missing",
                &format!("an integer in 1..={dofs}"),
            )
        })?;
        Ok(self.count("output.dof", dof, 1, dofs)? - 1)
    }
}
