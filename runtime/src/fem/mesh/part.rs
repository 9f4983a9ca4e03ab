//! One process's part of a mesh, in a run split across processes.

use super::{Body, Facet, Mesh, Region};

impl Mesh {
    /// The cells process `rank` assembles when node i belongs to process `owner[i]`: the cells
    /// it owns (those whose first node it owns) first, then the other cells with a node it owns,
    /// then every other cell that carries a facet of the regions named in `whole`, each group in
    /// mesh order. With all the cells of its nodes, the process's rows are complete; with those
    /// regions' cells, each process integrates over their facets whole (contact regions are a
    /// small part of a mesh), so the active set and the facet integrals are the same on every
    /// process without an exchange. The nodes, their coordinates and those regions' facet
    /// order are the whole mesh's; the other regions are left out (a facet integral over part
    /// of one would be wrong). Returns the part and how many of its cells the process owns.
    pub fn part(&self, owner: &[u32], rank: u32, whole: &[&str]) -> (Mesh, usize) {
        let cells = self.num_cells();
        let mut on_region = vec![false; cells];
        let kept_regions: Vec<&Region> = self.regions.iter().filter(|r| whole.contains(&r.name.as_str())).collect();
        for region in &kept_regions {
            region.facets.iter().for_each(|f| on_region[f.cell as usize] = true);
        }
        let owned = |c: usize| owner[self.cell(c)[0] as usize] == rank;
        let touches = |c: usize| self.cell(c).iter().any(|&n| owner[n as usize] == rank);
        let kept: Vec<usize> = (0..cells)
            .filter(|&c| owned(c))
            .chain((0..cells).filter(|&c| !owned(c) && touches(c)))
            .chain((0..cells).filter(|&c| !touches(c) && on_region[c]))
            .collect();
        let mut local = vec![u32::MAX; cells];
        kept.iter().enumerate().for_each(|(l, &c)| local[c] = l as u32);
        let regions = kept_regions
            .iter()
            .map(|r| Region {
                name: r.name.clone(),
                facets: r.facets.iter().map(|f| Facet { cell: local[f.cell as usize], local: f.local }).collect(),
            })
            .collect();
        let cell_groups = self
            .cell_groups
            .iter()
            .map(|(name, group)| {
                let mut mine: Vec<u32> = group.iter().map(|&c| local[c as usize]).filter(|&l| l != u32::MAX).collect();
                mine.sort_unstable();
                (name.clone(), mine)
            })
            .collect();
        let bodies = self
            .bodies
            .iter()
            .map(|b| Body {
                name: b.name.clone(),
                cells: kept.iter().map(|&c| b.cells[c]).collect(),
                nodes: b.nodes.clone(),
            })
            .collect();
        let part = Mesh {
            kind: self.kind,
            coords: self.coords.clone(),
            cells: kept.iter().flat_map(|&c| self.cell(c).iter().copied()).collect(),
            regions,
            cell_groups,
            bodies,
            warnings: self.warnings.clone(),
            cell_size: self.cell_size,
            sizes: if self.sizes.is_empty() { Vec::new() } else { kept.iter().map(|&c| self.sizes[c]).collect() },
        };
        let owned_count = kept.iter().take_while(|&&c| owned(c)).count();
        (part, owned_count)
    }
}
