#!/usr/bin/python3
"""An independent reference for cylinder.stp (validation/order2.md section 5): a structured
O-grid of C3D20 (a core block and four ring blocks, mid-edge nodes on the exact circle), graded
towards the clamped end face and the surface, solved by CalculiX *FREQUENCY (clamped at y = 177.5,
steel). Richardson over N = 6, 8, 12 gives f1 = f2 = 5182.13 Hz (the chain's cylinder.json says
5184.34: its fallback order of 4 where the observed order is below 1).

  /usr/bin/python3 validation/reference/cylinder_c20.py N M NY Q NAME [OUTDIR]
  e.g. 6 3 12 2 g_6; 8 4 16 2 g_8; 12 6 24 2 g_12   (core divisions, ring, axial, grading)
  /usr/bin/python3 validation/reference/cylinder_c20.py summarize OUT.json OUTDIR g_6 g_8 g_12
      writes OUT.json (validation/reference/cylinder_c20.json) from those runs

Free-free (REFERENCE_FREE=1, as for reference_chain.py; no singular edge, so no grading: Q = 1):
no *BOUNDARY, ccx asked for 6 more modes, the six rigid-body ones checked and dropped.
  REFERENCE_FREE=1 ... cylinder_c20.py 4 2 8 1 f_4; 6 3 12 1 f_6; 8 4 16 1 f_8
  REFERENCE_FREE=1 ... cylinder_c20.py summarize validation/reference/cylinder_free_c20.json OUTDIR f_4 f_6 f_8
"""
import numpy as np, sys, subprocess, os, time, json
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference_chain as chain
FREE = chain.free_free()
R=6.752432; L=42.5; CX=-67.75; CZ=-267.5; Y0=177.5


def mode_kinds(dat):
    """bending / torsion / axial per mode from ccx's effective modal mass (axis y): no
    translational mass -> torsion about y, mostly y -> axial, else bending."""
    lines = open(dat).read().split('\n')
    i = next(k for k, l in enumerate(lines) if 'E F F E C T I V E   M O D A L   M A S S' in l)
    rows = []
    for l in lines[i + 4:]:
        p = l.split()
        if not p or not p[0].isdigit():
            break
        rows.append([float(v) for v in p[1:4]])
    t = np.array(rows[chain.NRIGID:] if FREE else rows)
    scale = t.max()
    return ['torsion' if r.max() < 1e-6 * scale else 'axial' if r.argmax() == 1 else 'bending'
            for r in t]


def summarize(out, rundir, names):
    """cylinder_c20.json (the schema of cylinder.json) from the runs NAME.json in rundir:
    Richardson over the two finest grids with reference_chain.summarize (observed order where
    1 <= p <= 6, 1.5 below an observed 1, else 4; uncertainty: the spread to the finest run and
    to p = 1.5 and 4). h = L / NY, the nominal axial size (all divisions scale together)."""
    runs = []
    for nm in names:
        r = json.load(open(os.path.join(rundir, nm + '.json')))
        log = open(os.path.join(rundir, nm + '.log')).read().split()
        secs = float(log[log.index('Time:') + 1]) if 'Time:' in log else None
        runs.append({'h': L / r['ny'], 'grid': {k: r[k] for k in ('n', 'm', 'ny', 'q')},
                     'elements': r['ny'] * (r['n'] ** 2 + 4 * r['n'] * r['m']), 'dofs': r['dof'],
                     'frequencies_hz': r['f'],
                     # free-free, no elastic mode has translational effective mass: not named
                     'modes': None if FREE else mode_kinds(os.path.join(rundir, nm + '.dat')),
                     'seconds_ccx': secs, 'seconds_total': secs,
                     'command': ('REFERENCE_FREE=1 ' if FREE else '') +
                                'validation/reference/cylinder_c20.py %d %d %d %g %s'
                                % (r['n'], r['m'], r['ny'], r['q'], nm)})
    what = ('free-free: structured O-grid of C3D20, uniform (cylinder_c20.py, REFERENCE_FREE=1)'
            if FREE else 'clamped on the end face y = 177.5: structured O-grid of C3D20 graded '
            'towards the clamp and the surface (cylinder_c20.py)')
    doc = {'what': 'cylinder.stp (shared models; R 6.752432, L 42.5 along y), steel, ' + what +
                   ', Richardson over the two finest grids',
           'command': ('REFERENCE_FREE=1 ' if FREE else '') +
                      'validation/reference/cylinder_c20.py summarize ' + ' '.join([out, rundir] + names),
           'geometry': '/work/shared/models/cylinder.stp (rebuilt analytically: exact circle)',
           'units': 'mm, N, t (tonne), s: E in MPa, density in t/mm^3, frequencies in Hz',
           'material': {'E_MPa': 210000.0, 'nu': 0.3, 'density_t_per_mm3': 7.85e-9},
           'boundary': ('free-free (no fixed DOF); the six rigid-body modes dropped' if FREE else
                        'all nodes with y = 177.5 (= min y) fixed in x, y, z'),
           'element': 'CalculiX C3D20 (full integration), core block + 4 ring blocks, mid-edge '
                      'nodes on the exact circle; h = L / NY (nominal axial size)',
           'versions': chain.tool_versions(), 'runs': runs}
    doc = chain.summarize(doc, nref=6)
    kinds = [r['modes'] for r in doc['runs']]
    if any(k != kinds[0] for k in kinds):
        sys.exit('mode order differs between grids: %s' % kinds)
    if not FREE:
        doc['reference_modes'] = kinds[0]
    with open(out, 'w') as f:
        json.dump(doc, f, indent=2)
        f.write('\n')
    if not FREE:
        print('modes:', ', '.join(kinds[0]))
    print('wrote', out)


if len(sys.argv) >= 5 and sys.argv[1] == 'summarize':
    summarize(sys.argv[2], sys.argv[3], sys.argv[4:])
    sys.exit(0)
n,m,ny,q=int(sys.argv[1]),int(sys.argv[2]),int(sys.argv[3]),float(sys.argv[4])
name=sys.argv[5]; a=0.45*R
def grade(k,N,q): return 1-(1-k/N)**q   # clusters toward 1
# parameter arrays on the double grid (2N+1 points)
def dbl(N,f): return np.array([f(k/2.0,N) for k in range(2*N+1)])
tu=np.linspace(0,1,2*n+1)
sr=dbl(m,lambda k,N: grade(k,N,q))            # radial toward surface
yy=dbl(ny,lambda k,N: L*(k/N)**q)               # toward clamp y=0
def block(b):
    # returns (2n+1, 2n+1 or 2m+1) array of (x,z)
    if b==0:
        U,V=np.meshgrid(tu,tu,indexing='ij'); return np.stack([-a+2*a*U,-a+2*a*V],-1)
    th0=-np.pi/4+(b-1)*np.pi/2
    rot=np.array([[np.cos(th0+np.pi/4),-np.sin(th0+np.pi/4)],[np.sin(th0+np.pi/4),np.cos(th0+np.pi/4)]])
    T,S=np.meshgrid(tu,sr,indexing='ij')
    th=th0+T*np.pi/2
    Pin=np.stack([np.full_like(T,a),-a+2*a*T],-1)@rot.T
    Pout=np.stack([R*np.cos(th),R*np.sin(th)],-1)
    return (1-S)[...,None]*Pin+S[...,None]*Pout
nodes={}; coords=[]
def nid(p):
    k=tuple(np.round(np.asarray(p)*1e4).astype(np.int64).tolist())
    if k not in nodes: nodes[k]=len(coords)+1; coords.append(p)
    return nodes[k]
els=[]
# hex20 local: corners in (i,j,k) offsets 0/2 in double grid
corner=[(0,0,0),(2,0,0),(2,2,0),(0,2,0),(0,0,2),(2,0,2),(2,2,2),(0,2,2)]
edges=[(0,1),(1,2),(2,3),(3,0),(4,5),(5,6),(6,7),(7,4),(0,4),(1,5),(2,6),(3,7)]
for b in range(5):
    B=block(b); NI,NJ=B.shape[0],B.shape[1]
    for i in range(0,NI-1,2):
        for j in range(0,NJ-1,2):
            for k in range(0,len(yy)-1,2):
                P=lambda di,dj,dk: np.array([B[i+di,j+dj,0],yy[k+dk],B[i+di,j+dj,1]])
                c=[P(*o) for o in corner]
                ids=[nid(x) for x in c]
                for e0,e1 in edges:
                    o=[(corner[e0][t]+corner[e1][t])//2 for t in range(3)]
                    ids.append(nid(P(*o)))
                els.append(ids)
X=np.array(coords)+np.array([CX,Y0,CZ])
els=np.array(els)
# orientation
def jac_sign(e):
    p=X[e[:8]-1]; return np.linalg.det(np.array([p[1]-p[0],p[3]-p[0],p[4]-p[0]]))
flip=[0,3,2,1,4,7,6,5, 11,10,9,8, 15,14,13,12, 16,19,18,17]
for ii in range(len(els)):
    if jac_sign(els[ii])<0: els[ii]=els[ii][flip]
Xr=np.round(X,4); assert len(np.unique(Xr,axis=0))==len(X), 'dups'
rr=np.hypot(X[:,0]-CX,X[:,2]-CZ)
out=sys.argv[6] if len(sys.argv)>6 else 'validation/out/cylinder_c20'
os.makedirs(out,exist_ok=True); os.chdir(out)
with open(name+'.inp','w') as f:
    f.write('*NODE\n'); [f.write('%d,%.12g,%.12g,%.12g\n'%(i+1,*x)) for i,x in enumerate(X)]
    f.write('*ELEMENT,TYPE=C3D20,ELSET=E\n')
    for i,e in enumerate(els): s=[str(v) for v in e]; f.write('%d,%s,\n%s\n'%(i+1,','.join(s[:15]),','.join(s[15:])))
    fix=[] if FREE else [i+1 for i in range(len(X)) if abs(X[i,1]-Y0)<1e-9]
    if fix:
        f.write('*NSET,NSET=FIX\n'); [f.write('%d,\n'%i) for i in fix]
        f.write('*BOUNDARY\nFIX,1,3\n')
    nfreq=6+(chain.NRIGID if FREE else 0)
    f.write('*MATERIAL,NAME=S\n*ELASTIC\n210000,0.3\n*DENSITY\n7.85e-9\n*SOLID SECTION,ELSET=E,MATERIAL=S\n*STEP\n*FREQUENCY\n%d\n*END STEP\n'%nfreq)
print('nodes',len(X),'els',len(els),'dof',3*(len(X)-len(fix)),'max|r-R| on surface', np.abs(rr[rr>R-1e-3]-R).max(),flush=True)
t=time.time(); subprocess.run(['ccx','-i',name],stdout=open(name+'.log','w'),env=dict(os.environ,OMP_NUM_THREADS='1'))
txt=open(name+'.dat').read().split('\n'); fr=[]
for i,l in enumerate(txt):
    if 'E I G E N V A L U E   O U T P U T' in l:
        for ll in txt[i+6:i+6+nfreq]: fr.append(float(ll.split()[3]))
        break
if FREE:
    fr,_=chain.split_rigid(fr,6,name)
print(name,'ccx %.1f s'%(time.time()-t),' '.join('%.3f'%x for x in fr))
json.dump(dict(n=n,m=m,ny=ny,q=q,dof=3*(len(X)-len(fix)),elements=len(els),f=fr),open(name+'.json','w'))
